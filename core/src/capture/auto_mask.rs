//! The object mask of a capture from its own intensity and polarization,
//! for objects in front of a background that fills the image border. The
//! rule:
//!
//! 1. **Polarization.** The background's polarization — `(s1, s2) / s0`
//!    of the lit border pixels (brighter than [`LIT`]; darker ones have no
//!    usable DoP) — is fitted as an affine function of the position: an
//!    unpolarized background fits as 0, a sheet seen obliquely polarizes
//!    weakly with an AoP that turns slowly across the image. Border pixels
//!    more than three robust deviations off the fit are dropped and the fit
//!    repeated. A lit pixel is off the background where its `(s1, s2) / s0`
//!    lies further from the fit than twice the border's median distance
//!    (under Gaussian noise 6% of background pixels), and at least
//!    [`MIN_DOP`]; it is object where more than half of the lit pixels of
//!    its 5×5 window are off (noise five times lower, and unlike an
//!    average of the polarization this does not spread a strongly
//!    polarized object by the window's width).
//! 2. **Intensity.** `I = s0 / 2` as a fraction of full scale is split in
//!    two by Otsu's threshold; when at least [`CLEAR_BORDER`] of the border
//!    falls on one side, that side is background and the other object.
//!    Otherwise (a background lit unevenly, bright at one edge and dark at
//!    another) intensity does not tell object from background and is not
//!    used.
//! 3. The union of both; its 8-connected components with at least a tenth
//!    of the largest one's pixels (several objects of a scene, not specks),
//!    with their holes (background pieces that do not reach the image
//!    border) filled.
//!
//! Why both: an intensity window loses a dark glossy object on a bright
//! sheet where its highlights are as bright as the sheet, and a dark
//! object's body where it is as dark as the shadows; the object is
//! polarized there (specular reflection, and a dark body's diffuse light)
//! while the sheet is not, or differently. A bright matte object on a dark
//! background is weakly polarized, and intensity finds it. Fruit on a white
//! sheet lit from one side (`fruits_IMX250MZR.png`) has a border that is
//! bright at the bottom and dark at the top: intensity alone masks the
//! sheet, while the sheet's weak, slowly turning polarization fits the
//! background model and the fruit does not.

use crate::integral::Integral;
use crate::percentile::percentile;
use crate::regions::Regions;
use crate::stokes::Stokes;
use crate::{Image, Mask};
use rayon::prelude::*;
use serde_json::json;

/// Pixels darker than this fraction of full scale have no usable DoP.
pub const LIT: f64 = 0.02;

/// The polarization threshold is never below this (sensor noise alone
/// reaches it).
pub const MIN_DOP: f64 = 0.05;

/// Least share of the border on one side of the intensity threshold for
/// intensity to tell object from background.
pub const CLEAR_BORDER: f64 = 0.9;

/// Half-width of the window whose majority decides (5×5).
const WINDOW: usize = 2;

/// Bins of the histograms Otsu's threshold is found on.
const BINS: usize = 256;

/// A mask found by the rule of the module doc, with its thresholds.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoMask {
    pub mask: Mask,
    /// Intensity threshold (fraction of full scale) and whether the object
    /// is the brighter side.
    pub intensity: f64,
    pub object_brighter: bool,
    /// Whether the border was clear enough for intensity to be used.
    pub intensity_used: bool,
    /// Least distance of a pixel's `(s1, s2) / s0` from the background's for
    /// it to be off the background.
    pub polarization: f64,
    /// The background's `(s1, s2) / s0` at the image centre.
    pub background: [f64; 2],
}

impl AutoMask {
    /// The rule's figures for `meta.json`.
    pub fn to_json(&self) -> serde_json::Value {
        json!({
            "rule": "object = most of the 5x5 window's lit pixels have (s1, s2)/s0 further from \
                     the border's affine fit than twice the border's median distance (at least \
                     0.05), or the side of Otsu's \
                     intensity threshold not on the border when 90% of the border is on one side; \
                     8-connected pieces of at least a tenth of the largest, holes filled",
            "intensity_threshold": self.intensity,
            "object_brighter": self.object_brighter,
            "intensity_used": self.intensity_used,
            "polarization_threshold": self.polarization,
            "background_polarization": self.background,
        })
    }
}

/// The mask of the objects in `pol` (0°, 45°, 90°, 135°, codes up to
/// `full`); see the module doc.
pub fn auto_mask(pol: &[Image<u16>; 4], full: u16) -> AutoMask {
    let (w, h) = pol[0].size();
    let k = 1.0 / f64::from(full);
    let stokes: Vec<Stokes> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let v = pol.each_ref().map(|p| f64::from(p.data()[i]) * k);
            Stokes::from_four(v[0], v[1], v[2], v[3])
        })
        .collect();
    let stokes = Image::from_vec(w, h, stokes).expect("one Stokes vector per pixel");
    let intensity = stokes.map(|s| s.unpolarized());
    let lit = intensity.map(|&i| i >= LIT);
    let border: Vec<usize> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| x == 0 || y == 0 || x + 1 == w || y + 1 == h)
        .map(|(x, y)| y * w + x)
        .collect();

    // 1. Polarization against the background's.
    let q = stokes.map(|s| if s.s0 > 0.0 { s.s1 / s.s0 } else { 0.0 });
    let u = stokes.map(|s| if s.s0 > 0.0 { s.s2 / s.s0 } else { 0.0 });
    let lit_border: Vec<usize> = border.iter().copied().filter(|&i| lit.data()[i]).collect();
    let fit = BackgroundFit::new(&q, &u, &lit_border);
    let distance = Image::from_fn(w, h, |x, y| {
        let [bq, bu] = fit.at(x, y, w, h);
        (q.get(x, y) - bq).hypot(u.get(x, y) - bu)
    });
    let on_border: Vec<f32> = lit_border
        .iter()
        .map(|&i| distance.data()[i] as f32)
        .collect();
    let t_pol = (2.0 * f64::from(percentile(&on_border, 0.5))).max(MIN_DOP);
    // Per window: lit pixels off the background, lit pixels.
    let votes = Integral::new(w, h, |i| {
        let off = lit.data()[i] && distance.data()[i] > t_pol;
        [f64::from(u8::from(off)), f64::from(u8::from(lit.data()[i]))]
    });

    // 2. Intensity, when the border is on one side of its threshold.
    let t_i = otsu(intensity.data().iter().copied()).unwrap_or(0.5);
    let above = border
        .iter()
        .filter(|&&i| intensity.data()[i] > t_i)
        .count() as f64
        / border.len().max(1) as f64;
    let object_brighter = above < 0.5;
    let intensity_used = above.max(1.0 - above) >= CLEAR_BORDER;

    let candidate = Image::from_fn(w, h, |x, y| {
        let i = y * w + x;
        let [off, lit_here] = votes.window(x, y, WINDOW);
        let polarized = lit.data()[i] && off > 0.5 * lit_here;
        let by_intensity = intensity_used && (intensity.data()[i] > t_i) == object_brighter;
        polarized || by_intensity
    });
    AutoMask {
        mask: fill_holes(&large_components(&candidate)),
        intensity: t_i,
        object_brighter,
        intensity_used,
        polarization: t_pol,
        background: fit.at(w / 2, h / 2, w, h),
    }
}

/// The background's `(s1, s2) / s0` as an affine function of the position
/// `(x / w, y / h)`, fitted by least squares.
struct BackgroundFit {
    q: [f64; 3],
    u: [f64; 3],
}

impl BackgroundFit {
    /// The fit over the pixels `at` (row-major indices); unpolarized when
    /// there are fewer than three.
    fn new(q: &Image<f64>, u: &Image<f64>, at: &[usize]) -> Self {
        let (w, h) = q.size();
        let basis = |i: usize| [1.0, (i % w) as f64 / w as f64, (i / w) as f64 / h as f64];
        let mut fit = BackgroundFit {
            q: [0.0; 3],
            u: [0.0; 3],
        };
        let mut kept: Vec<usize> = at.to_vec();
        for _ in 0..2 {
            let (Some(cq), Some(cu)) = (
                affine_fit(kept.iter().map(|&i| (basis(i), q.data()[i]))),
                affine_fit(kept.iter().map(|&i| (basis(i), u.data()[i]))),
            ) else {
                break;
            };
            fit = BackgroundFit { q: cq, u: cu };
            let off = |i: usize| {
                let [bq, bu] = fit.at(i % w, i / w, w, h);
                (q.data()[i] - bq).hypot(u.data()[i] - bu)
            };
            let offs: Vec<f32> = kept.iter().map(|&i| off(i) as f32).collect();
            // 1.4826 × median: one deviation of Gaussian noise.
            let limit = 3.0 * 1.4826 * f64::from(percentile(&offs, 0.5));
            kept.retain(|&i| off(i) <= limit);
        }
        fit
    }

    fn at(&self, x: usize, y: usize, w: usize, h: usize) -> [f64; 2] {
        let b = [1.0, x as f64 / w as f64, y as f64 / h as f64];
        let dot = |c: &[f64; 3]| c[0] * b[0] + c[1] * b[1] + c[2] * b[2];
        [dot(&self.q), dot(&self.u)]
    }
}

/// Least-squares coefficients of `value ≈ c · basis` over the samples;
/// `None` when their normal matrix is singular.
fn affine_fit(samples: impl Iterator<Item = ([f64; 3], f64)>) -> Option<[f64; 3]> {
    let (mut m, mut r) = ([[0.0f64; 3]; 3], [0.0f64; 3]);
    for (b, v) in samples {
        for j in 0..3 {
            r[j] += b[j] * v;
            for k in 0..3 {
                m[j][k] += b[j] * b[k];
            }
        }
    }
    // Cramer's rule on the 3×3 normal equations.
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d.abs() < 1e-12 * (m[0][0] * m[1][1] * m[2][2]).abs().max(1e-300) {
        return None;
    }
    Some(std::array::from_fn(|c| {
        let mut mc = m;
        for (row, &rj) in mc.iter_mut().zip(&r) {
            row[c] = rj;
        }
        det(&mc) / d
    }))
}

/// Otsu's threshold of `values` in `[0, 1]`: the bin edge that maximizes
/// the between-class variance of a 256-bin histogram. `None` without
/// values or when all fall in one bin.
fn otsu(values: impl Iterator<Item = f64>) -> Option<f64> {
    let mut hist = [0u64; BINS];
    for v in values {
        hist[((v.clamp(0.0, 1.0) * BINS as f64) as usize).min(BINS - 1)] += 1;
    }
    let total: u64 = hist.iter().sum();
    let weighted: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &n)| i as f64 * n as f64)
        .sum();
    let (mut below, mut below_sum) = (0u64, 0.0);
    let mut best: Option<(f64, usize)> = None;
    for (i, &n) in hist.iter().enumerate().take(BINS - 1) {
        below += n;
        below_sum += i as f64 * n as f64;
        let above = total - below;
        if below == 0 || above == 0 {
            continue;
        }
        let (m0, m1) = (
            below_sum / below as f64,
            (weighted - below_sum) / above as f64,
        );
        let between = below as f64 * above as f64 * (m0 - m1).powi(2);
        if best.is_none_or(|(b, _)| between > b) {
            best = Some((between, i));
        }
    }
    best.map(|(_, i)| (i + 1) as f64 / BINS as f64)
}

/// The 8-connected components of `mask` with at least a tenth of the
/// largest one's pixels.
fn large_components(mask: &Mask) -> Mask {
    let regions = Regions::components(mask);
    let largest = regions
        .list
        .iter()
        .map(|r| r.pixels.len())
        .max()
        .unwrap_or(0);
    let mut out = Mask::new(mask.width(), mask.height(), false);
    for region in regions
        .list
        .iter()
        .filter(|r| r.pixels.len() * 10 >= largest)
    {
        for &i in &region.pixels {
            out.data_mut()[i] = true;
        }
    }
    out
}

/// `mask` with every background piece (8-connected) that does not reach the
/// image border made object.
fn fill_holes(mask: &Mask) -> Mask {
    let (w, h) = mask.size();
    let background = Regions::components(&mask.map(|&m| !m));
    let mut out = mask.clone();
    for region in &background.list {
        let reaches_border =
            region.x0 == 0 || region.y0 == 0 || region.x1 + 1 == w || region.y1 + 1 == h;
        if !reaches_border {
            for &i in &region.pixels {
                out.data_mut()[i] = true;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    /// A 96² 12-bit capture: a disc of radius 30 (its pixels by `disc`) in
    /// front of an unpolarized background of intensity `bg`.
    fn capture(bg: f64, disc: impl Fn(f64, f64) -> Stokes) -> ([Image<u16>; 4], Mask) {
        scene(
            |x, y| (x.hypot(y) < 30.0).then(|| disc(x, y)),
            |_, _| Stokes::new(2.0 * bg, 0.0, 0.0),
        )
    }

    /// A 96² 12-bit capture of `object` where it is `Some` in front of
    /// `background` (both given centred coordinates, y up), with Gaussian
    /// noise of 4 codes per image from a seeded generator; the object's
    /// pixels.
    fn scene(
        object: impl Fn(f64, f64) -> Option<Stokes>,
        background: impl Fn(f64, f64) -> Stokes,
    ) -> ([Image<u16>; 4], Mask) {
        let n = 96;
        let full = 4095.0;
        let mut rng = Pcg64::seed_from_u64(7);
        let at = |x: usize, y: usize| (x as f64 - 48.0, 48.0 - y as f64);
        let truth = Mask::from_fn(n, n, |x, y| {
            let (x, y) = at(x, y);
            object(x, y).is_some()
        });
        let stokes = Image::from_fn(n, n, |x, y| {
            let (x, y) = at(x, y);
            object(x, y).unwrap_or_else(|| background(x, y))
        });
        let pol = std::array::from_fn(|i| {
            let angle = crate::stokes::STANDARD_ANGLES[i];
            stokes.map(|s| {
                let v = s.through_polarizer(angle) * full + 4.0 * gauss(&mut rng);
                v.round().clamp(0.0, full) as u16
            })
        });
        (pol, truth)
    }

    /// A standard normal draw (Box–Muller).
    fn gauss(rng: &mut Pcg64) -> f64 {
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    fn errors(found: &Mask, truth: &Mask) -> usize {
        found
            .data()
            .iter()
            .zip(truth.data())
            .filter(|(a, b)| a != b)
            .count()
    }

    #[test]
    fn otsu_splits_two_levels_between_them() {
        let values = [0.2; 50].into_iter().chain([0.7; 30]);
        let t = otsu(values).unwrap();
        assert!(t > 0.2 && t <= 0.7, "{t}");
        assert_eq!(otsu([0.4; 10].into_iter()), None);
    }

    /// A dark glossy sphere on a bright unpolarized sheet: a dark body with
    /// a strongly polarized rim, and a highlight as bright as the sheet.
    /// An intensity window loses the highlight; the rule keeps the disc.
    #[test]
    fn dark_glossy_object_on_a_bright_sheet() {
        let (pol, truth) = capture(0.7, |x, y| {
            let r = x.hypot(y) / 30.0;
            let highlight = (x - 8.0).hypot(y - 8.0) < 6.0;
            let i = if highlight { 0.72 } else { 0.08 };
            Stokes::from_polarization(2.0 * i, 0.2 + 0.5 * r * r, y.atan2(x))
        });
        let found = auto_mask(&pol, 4095);
        assert!(!found.object_brighter && found.intensity_used, "{found:?}");
        assert_eq!(errors(&found.mask, &truth), 0);
        let window = Mask::from_fn(96, 96, |x, y| {
            let mean = pol.iter().map(|p| f64::from(*p.get(x, y))).sum::<f64>() / 4.0 / 4095.0;
            mean < 0.3
        });
        assert!(
            errors(&window, &truth) > 80,
            "the window keeps the highlight"
        );
    }

    /// A bright matte object (weak DoP) on a dark unpolarized background,
    /// whose noisy DoP must not leak into the mask.
    #[test]
    fn bright_matte_object_on_a_dark_background() {
        let (pol, truth) = capture(0.01, |x, y| {
            let r = x.hypot(y) / 30.0;
            Stokes::from_polarization(1.2, 0.1 * r * r, y.atan2(x))
        });
        let found = auto_mask(&pol, 4095);
        assert!(found.object_brighter && found.intensity_used, "{found:?}");
        assert_eq!(errors(&found.mask, &truth), 0);
    }

    /// Two objects on a sheet lit from below (dark at the top border,
    /// bright at the bottom one) that polarizes weakly with an AoP turning
    /// across the image: intensity cannot tell them apart, the
    /// polarization against the border's fit does. Their DoP ranges from
    /// 0.1 at the centre to 0.4 at the rim, the sheet's is 0.07.
    #[test]
    fn objects_on_an_unevenly_lit_polarizing_sheet() {
        let disc = |x: f64, y: f64, cx: f64, r: f64| {
            let (dx, dy) = (x - cx, y - 4.0);
            let rr = dx.hypot(dy) / r;
            (rr < 1.0).then(|| Stokes::from_polarization(0.8, 0.1 + 0.3 * rr * rr, dy.atan2(dx)))
        };
        let (pol, truth) = scene(
            |x, y| disc(x, y, -20.0, 18.0).or_else(|| disc(x, y, 22.0, 14.0)),
            |x, y| {
                let i = 0.4 - 0.3 * y / 48.0;
                Stokes::from_polarization(2.0 * i, 0.07, 1.6 + 0.4 * x / 48.0)
            },
        );
        let found = auto_mask(&pol, 4095);
        assert!(!found.intensity_used, "{found:?}");
        assert!(
            errors(&found.mask, &truth) * 50 < truth.count(),
            "{} of {} wrong",
            errors(&found.mask, &truth),
            truth.count()
        );
    }

    #[test]
    fn holes_are_filled_and_specks_dropped() {
        let ring = Mask::from_fn(12, 12, |x, y| {
            let r = (x as f64 - 5.5).hypot(y as f64 - 5.5);
            (2.0..5.0).contains(&r) || (x, y) == (11, 0)
        });
        let filled = fill_holes(&large_components(&ring));
        assert!(*filled.get(5, 5) && !*filled.get(11, 0));
        assert_eq!(
            filled.count(),
            Mask::from_fn(12, 12, |x, y| (x as f64 - 5.5).hypot(y as f64 - 5.5) < 5.0).count()
        );
    }
}
