//! Does the labelling of a capture's four polarizer images fit the data?
//! A mosaic pattern or file order that is valid but wrong imports without
//! error and gives wrong normals (a 90°/135° swap turns a 4° result into
//! 30°), so the capture is checked against itself in two steps:
//!
//! 1. **Pairing** (conventions.md §2): for any light `I0 + I90 = I45 + I135
//!    = s0`. Of the three ways to split four images into two pairs only the
//!    crossed pairs {0°, 90°}, {45°, 135°} satisfy it; the other two leave
//!    the polarized part `s1 ± s2` as a residual. The split with the
//!    smallest RMS residual fits, and that residual is the sensor's noise
//!    (plus the sub-pixel offsets of a mosaic's photosites), so the labelled
//!    split fits when its residual is within [`NOISE_RATIO`] times it.
//! 2. **Orientation**: the eight orders within one split give the same DoP
//!    and an AoP turned by a multiple of 45° or mirrored; the sum rule
//!    cannot see them. A matte object is polarized along its outward normal
//!    at its silhouette (conventions.md §3), so with an object mask the
//!    order whose AoP follows the outline, `mean cos 2(ψ − φ)` near 1, fits.
//!    Without a mask, or when no single order clearly follows the outline, the
//!    orientation is left unchecked and a wrong split is answered with the
//!    orders of the right split closest to the labelled one.

use crate::stokes::Stokes;
use crate::{Image, Mask};
use rayon::prelude::*;
use serde_json::json;

/// The labelled split may leave an RMS residual up to this many times the
/// best split's (the noise) and still fit. A wrong split leaves `s1 ± s2`:
/// 2.6 to 6.3 times the noise on the real captures (the right split of a
/// Sony mosaic pairs diagonal photosites, so its residual also holds their
/// sub-pixel offset), thousands of times on noise-free synthetic ones.
pub const NOISE_RATIO: f64 = 2.0;

/// The best order's outline agreement must reach this for the silhouette
/// to decide the orientation (a right order gives 0.4–1 on a matte object;
/// specular or cut-off outlines give less, and then it does not decide).
pub const ORIENTED: f64 = 0.3;

/// The best order must beat every other by this much for the outline to
/// decide (a wrong orientation gives about 0 or −1 on a round outline, but
/// a weak or cut-off outline leaves several orders close together).
pub const MARGIN: f64 = 0.5;

/// Largest RMS residual of the labelled split (`I0 + I90 − I45 − I135`, a
/// fraction of the mean `s0`) of images that are one polarization
/// measurement. Any capture leaves only its noise there: 1e-5 on noise-free
/// views (the rounding of the codes), 0.013–0.016 in the mask of the
/// built-in views at their default noise; four unrelated images leave the
/// spread of their values, 0.49 for uniform noise. Beyond it the DoP's
/// noise (about the residual / √2) exceeds the diffuse DoP of most of an
/// object, so nothing polarimetric is left to reconstruct.
pub const MAX_RESIDUAL: f64 = 0.25;

/// The standard angles, in degrees, of the indices 0..4.
const ANGLES: [u16; 4] = [0, 45, 90, 135];

/// An assignment of the four imported images to the standard polarizer
/// angles: `self.0[a]` is the image (indexed by the angle it was labelled
/// with, 0°, 45°, 90°, 135°) that was taken at angle `a`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AngleOrder(pub [usize; 4]);

impl AngleOrder {
    /// Every image at the angle it was labelled with.
    pub const LABELLED: AngleOrder = AngleOrder([0, 1, 2, 3]);

    /// Every order of four images (24).
    pub fn all() -> Vec<AngleOrder> {
        (0..256usize)
            .map(|code| AngleOrder(std::array::from_fn(|a| (code >> (2 * a)) & 3)))
            .filter(|o| (0..4).all(|k| o.0.contains(&k)))
            .collect()
    }

    /// The images in this order: `result[a] = images[self.0[a]]`.
    pub fn apply<T: Clone>(self, images: &[T; 4]) -> [T; 4] {
        std::array::from_fn(|a| images[self.0[a]].clone())
    }

    /// The angle index each image was taken at: `result[image] = angle`.
    pub fn inverse(self) -> [usize; 4] {
        let mut inv = [0; 4];
        for (a, &image) in self.0.iter().enumerate() {
            inv[image] = a;
        }
        inv
    }

    /// Images at the angle they were labelled with.
    fn fixed_points(self) -> usize {
        (0..4).filter(|&a| self.0[a] == a).count()
    }

    /// The eight orders whose crossed pairs are {0, `partner`} and the
    /// other two images.
    fn with_partner(partner: usize) -> Vec<AngleOrder> {
        let [p, q] = match partner {
            1 => [2, 3],
            2 => [1, 3],
            _ => [1, 2],
        };
        let mut orders = Vec::with_capacity(8);
        for (a, b) in [(0, partner), (partner, 0), (p, q), (q, p)] {
            let (c, d) = if a == 0 || b == 0 {
                (p, q)
            } else {
                (0, partner)
            };
            orders.push(AngleOrder([a, c, b, d]));
            orders.push(AngleOrder([a, d, b, c]));
        }
        orders
    }

    /// In words: which labelled image was taken at which angle.
    pub fn describe(self) -> String {
        let inv = self.inverse();
        let moved: Vec<String> = (0..4)
            .filter(|&k| inv[k] != k)
            .map(|k| format!("{}° is {}°", ANGLES[k], ANGLES[inv[k]]))
            .collect();
        if moved.is_empty() {
            "as labelled".into()
        } else {
            format!("the image labelled {}", moved.join(", the one labelled "))
        }
    }
}

/// The outcome of [`check`], recorded in a capture's `meta.json`.
#[derive(Clone, Debug, PartialEq)]
pub struct PatternCheck {
    /// Pixels the sum rule was measured over.
    pub pixels: usize,
    /// RMS of `I0 + Ik − (the other two)` over those pixels, as a fraction
    /// of the mean `s0`, for the image labelled 0° paired with the one
    /// labelled 45°, 90° (the labelled split) and 135°.
    pub sum_rule: [f64; 3],
    /// Outline agreement `mean cos 2(ψ − φ)` of the labelled order, when
    /// there is a mask with enough polarized outline pixels.
    pub silhouette: Option<f64>,
    /// The orders that fit the data, best first (several when the data
    /// cannot tell them apart).
    pub fits: Vec<AngleOrder>,
    /// Whether the outline decided the orientation.
    pub oriented: bool,
}

/// The split of [`PatternCheck::sum_rule`] with the smallest residual.
fn best_split(sum_rule: &[f64; 3]) -> usize {
    (0..3)
        .min_by(|&a, &b| sum_rule[a].total_cmp(&sum_rule[b]))
        .expect("three splits")
}

/// The labelled split's residual is within [`NOISE_RATIO`] times the best
/// one's (and 10⁻⁴ of `s0`, the rounding of noise-free codes).
fn split_fits(sum_rule: &[f64; 3]) -> bool {
    sum_rule[1] <= NOISE_RATIO * sum_rule[best_split(sum_rule)] + 1e-4
}

impl PatternCheck {
    /// The labelled images pair up as crossed polarizers as the sum rule
    /// wants ({0°, 90°} and {45°, 135°}).
    pub fn labelled_split_fits(&self) -> bool {
        split_fits(&self.sum_rule)
    }

    /// The labelled images are one polarization measurement: crossed
    /// pairs that sum to the same `s0` within [`MAX_RESIDUAL`] (a relative
    /// check, as [`PatternCheck::labelled_split_fits`], cannot tell four
    /// unrelated images apart, since every split fits them equally badly).
    pub fn consistent(&self) -> bool {
        self.sum_rule[1] <= MAX_RESIDUAL
    }

    /// The smallest RMS residual of the three splits: the noise.
    pub fn noise(&self) -> f64 {
        self.sum_rule[best_split(&self.sum_rule)]
    }

    /// The labelled order is among those that fit.
    pub fn labelled_fits(&self) -> bool {
        self.fits.contains(&AngleOrder::LABELLED)
    }

    /// The figures as JSON for `meta.json`.
    pub fn to_json(&self) -> serde_json::Value {
        json!({
            "pixels": self.pixels,
            "sum_rule_rms": {
                "0+45=90+135": self.sum_rule[0],
                "0+90=45+135": self.sum_rule[1],
                "0+135=45+90": self.sum_rule[2],
            },
            "noise_ratio": NOISE_RATIO,
            "silhouette_aop_agreement": self.silhouette,
            "orientation_checked": self.oriented,
            "labelled_fits": self.labelled_fits(),
            "fits": self.fits.iter().map(|o| o.describe()).collect::<Vec<_>>(),
        })
    }
}

/// Checks the labelling of `pol` (0°, 45°, 90°, 135° as labelled, codes up
/// to `full`): the sum rule over the pixels of `pixels` (all when `None`;
/// the whole unsaturated frame, not just the object, as a polarized
/// background helps tell the pairings apart), the orientation by the
/// outline of `object` (an object mask, not the outline of saturated
/// pixels). See the module doc.
pub fn check(
    pol: &[Image<u16>; 4],
    full: u16,
    pixels: Option<&Mask>,
    object: Option<&Mask>,
) -> PatternCheck {
    let (count, sum_rule) = sum_rule(pol, pixels);
    let partner = if split_fits(&sum_rule) {
        2
    } else {
        best_split(&sum_rule) + 1
    };
    let orders = AngleOrder::with_partner(partner);
    let outline = object.map(|m| Outline::collect(pol, full, m));
    let silhouette = outline
        .as_ref()
        .and_then(|o| o.agreement(AngleOrder::LABELLED));
    let mut scored: Vec<(AngleOrder, f64)> = outline
        .as_ref()
        .map(|o| {
            orders
                .iter()
                .filter_map(|&order| o.agreement(order).map(|a| (order, a)))
                .collect()
        })
        .unwrap_or_default();
    scored.sort_by(|a, b| b.1.total_cmp(&a.1));
    // One order must follow the outline, clearly better than every other.
    let oriented = match scored.as_slice() {
        [(_, best), rest @ ..] => {
            *best >= ORIENTED && rest.first().is_none_or(|(_, next)| *next <= best - MARGIN)
        }
        [] => false,
    };
    let fits = if oriented {
        vec![scored[0].0]
    } else if partner == 2 {
        vec![AngleOrder::LABELLED]
    } else {
        let most = orders.iter().map(|o| o.fixed_points()).max().unwrap_or(0);
        orders
            .into_iter()
            .filter(|o| o.fixed_points() == most)
            .collect()
    };
    PatternCheck {
        pixels: count,
        sum_rule,
        silhouette,
        fits,
        oriented,
    }
}

/// Pixel count and the relative RMS residual of the three splits (image 0
/// with image 1, 2, 3) over `mask`; rows are summed in parallel and added
/// in order, so the figures do not depend on the thread count.
fn sum_rule(pol: &[Image<u16>; 4], mask: Option<&Mask>) -> (usize, [f64; 3]) {
    let (w, h) = pol[0].size();
    let rows: Vec<[f64; 5]> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut acc = [0.0; 5];
            for x in 0..w {
                if mask.is_some_and(|m| !*m.get(x, y)) {
                    continue;
                }
                let v = pol.each_ref().map(|p| f64::from(*p.get(x, y)));
                let total = v.iter().sum::<f64>();
                for (k, r) in acc[..3].iter_mut().enumerate() {
                    let paired = v[0] + v[k + 1];
                    *r += (2.0 * paired - total).powi(2);
                }
                acc[3] += 0.5 * total;
                acc[4] += 1.0;
            }
            acc
        })
        .collect();
    let mut acc = [0.0; 5];
    for row in &rows {
        for (a, r) in acc.iter_mut().zip(row) {
            *a += r;
        }
    }
    let n = acc[4];
    let mean_s0 = acc[3] / n;
    if n == 0.0 || mean_s0 <= 0.0 {
        return (0, [0.0; 3]);
    }
    (
        n as usize,
        std::array::from_fn(|k| (acc[k] / n).sqrt() / mean_s0),
    )
}

/// The four values and outward direction `φ` of every outline pixel of a
/// mask that is lit (`s0` above 2% of full scale).
struct Outline {
    samples: Vec<([f64; 4], f64)>,
}

impl Outline {
    fn collect(pol: &[Image<u16>; 4], full: u16, mask: &Mask) -> Outline {
        let (w, h) = mask.size();
        let k = 1.0 / f64::from(full);
        let mut samples = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let Some([ox, oy]) = mask.outward_direction(x, y, 2) else {
                    continue;
                };
                let v = pol.each_ref().map(|p| f64::from(*p.get(x, y)) * k);
                if 0.5 * v.iter().sum::<f64>() > 0.02 {
                    samples.push((v, oy.atan2(ox)));
                }
            }
        }
        Outline { samples }
    }

    /// Mean `cos 2(ψ − φ)` over the samples with a DoP of at least 0.05
    /// when the images are in `order`; `None` with fewer than 20 of them.
    fn agreement(&self, order: AngleOrder) -> Option<f64> {
        let (mut sum, mut count) = (0.0, 0usize);
        for (v, phi) in &self.samples {
            let [i0, i45, i90, i135] = order.apply(v);
            let st = Stokes::from_four(i0, i45, i90, i135);
            if st.dop() >= 0.05 {
                sum += (2.0 * (st.aop() - phi)).cos();
                count += 1;
            }
        }
        (count >= 20).then(|| sum / count as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::AnalyticScene;

    /// The image paired with image 0 as crossed polarizers (1, 2 or 3).
    fn partner_of_first(order: AngleOrder) -> usize {
        order.0[(order.inverse()[0] + 2) % 4]
    }

    #[test]
    fn orders_of_a_split_and_their_words() {
        for partner in 1..4 {
            let orders = AngleOrder::with_partner(partner);
            assert_eq!(orders.len(), 8);
            for o in &orders {
                assert_eq!(partner_of_first(*o), partner, "{o:?}");
                let mut sorted = o.0;
                sorted.sort();
                assert_eq!(sorted, [0, 1, 2, 3]);
            }
            let mut distinct = orders.clone();
            distinct.dedup();
            assert_eq!(distinct.len(), 8);
        }
        assert_eq!(AngleOrder::all().len(), 24);
        assert_eq!(AngleOrder::LABELLED.describe(), "as labelled");
        let swapped = AngleOrder([0, 1, 3, 2]);
        assert_eq!(
            swapped.describe(),
            "the image labelled 90° is 135°, the one labelled 135° is 90°"
        );
        assert_eq!(swapped.apply(&["a", "b", "c", "d"]), ["a", "b", "d", "c"]);
    }

    /// A closed-form capture: a matte sphere (analytic view, 16-bit codes)
    /// relabelled with every one of the 24 orders. The labelled order fits
    /// only when it is the true one; otherwise the check names the true
    /// order, with the mask, and without it at least the true split.
    #[test]
    fn every_wrong_order_of_a_sphere_is_found() {
        let view = AnalyticScene {
            size: 64,
            light: [0.3, 0.2, 1.0],
            ..AnalyticScene::default()
        }
        .render()
        .unwrap();
        let truth = view.input.pol.clone();
        let mask = view.input.mask.clone().unwrap();
        for order in AngleOrder::all() {
            // Labelled image k holds the true image at angle `order.0[k]`,
            // so the order that puts them back is its inverse.
            let labelled: [Image<u16>; 4] = std::array::from_fn(|k| truth[order.0[k]].clone());
            let back = AngleOrder(order.inverse());
            let c = check(&labelled, u16::MAX, Some(&mask), Some(&mask));
            assert!(c.oriented, "{order:?}: {c:?}");
            assert_eq!(c.fits, vec![back], "{order:?}: {c:?}");
            assert_eq!(c.labelled_fits(), order == AngleOrder::LABELLED);
            let true_split = partner_of_first(back) - 1;
            for k in 0..3 {
                if k == true_split {
                    assert!(c.sum_rule[k] < 1e-4, "{c:?}");
                } else {
                    assert!(c.sum_rule[k] > 0.05, "{c:?}");
                }
            }
            // Without an outline the split is still found.
            let c = check(&labelled, u16::MAX, None, None);
            assert!(!c.oriented && c.silhouette.is_none());
            assert!(
                c.fits
                    .iter()
                    .all(|o| partner_of_first(*o) == true_split + 1)
            );
            assert_eq!(c.labelled_fits(), partner_of_first(back) == 2, "{c:?}");
        }
    }

    #[test]
    fn a_dark_or_unpolarized_capture_is_left_alone() {
        let flat: [Image<u16>; 4] = std::array::from_fn(|_| Image::new(8, 8, 500u16));
        let c = check(&flat, u16::MAX, None, None);
        assert_eq!(c.sum_rule, [0.0; 3]);
        assert!(c.labelled_fits());
        let black: [Image<u16>; 4] = std::array::from_fn(|_| Image::new(8, 8, 0u16));
        let c = check(&black, u16::MAX, None, None);
        assert_eq!((c.pixels, c.labelled_fits()), (0, true));
    }
}
