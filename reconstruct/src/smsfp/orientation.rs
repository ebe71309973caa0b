//! Step 6 of SMSfP (module doc), beyond the paper: the AoP oriented by
//! continuity, for the regions their trusted contours do not hold.
//!
//! A region without an occluding contour (a relief whose rim is a crease,
//! a piece cut out by the segmentation) has no convexity prior, so its
//! system holds only the azimuth rows, which are blind to the sense, and
//! the shading rows, which carry the sense only as far as the light is
//! off the view: under a light along the view every row is homogeneous
//! and the solve is flat (analytic blobs 128², frontal light: 22.7° MAE
//! whatever the noise, the mean zenith, with half the per-pixel azimuths
//! turned). Yet the sense is not free: a smooth surface's gradient can
//! only turn its sense where the gradient vanishes, so the AoP's line
//! field, oriented by continuity, is the gradient's direction up to one
//! sign per region.
//!
//! The orientation is a maximum spanning forest (Kruskal) over the region's
//! 4-neighbour pairs: a pair weighs `min(s_i, s_j) |cos(ψ_i − ψ_j)|`, `s`
//! each pixel's AoP confidence (its azimuth row's noise weight) times
//! `sin θ` (the gradient vanishes at a peak or pit, where its direction
//! turns at once), and joins its pixels in the sense that keeps their
//! azimuths within 90°, so the sense travels along the best-measured,
//! steepest paths and around the peaks and noisy rims. The region's sign is the one whose normals (the zenith
//! of the DoP) explain the intensities better under the estimated light;
//! on a tie (a light along the view) the one that bends away from the
//! camera towards the region's outline. That sign goes with the light's
//! convex/concave member (`system::RelativePrior`): the flipped light gets
//! the opposite sense, and the object's contours choose between them.
//!
//! The oriented azimuths enter the region's system as zenith rows (the
//! prior's rows, `cos θ z_x = −sin θ cos φ`), each weighted by its pixel's
//! confidence and by how far the trusted contours leave the region free
//! (`1 − release`, the complement of the azimuth rows' release in
//! `region`): a region held by its contours keeps its prior alone.
//! Analytic blobs, 128², frontal light, 36 noise seeds: 1250 e⁻ 23.16° →
//! 20.45°, 5000 e⁻ 23.12° → 10.94°, 20000 e⁻ 21.61° → 5.67°; noise-free
//! 9.34° → 0.14°; the analytic sphere (held by its limb) unchanged.

use crate::input::Input;
use crate::light::Lighting;
use crate::parity_union::ParityUnion;
use crate::prior::convexity_prior;
use crate::solver::domain::Domain;
use crate::system::RelativePrior;
use sfp_core::Image;

/// The oriented-AoP rows of a region whose contours leave `free` (0 to 1)
/// of it to them, or `None` when nothing is free or nothing is measured.
/// `confidence` is each window pixel's AoP confidence in `[0, 1]`, `theta`
/// the zenith at the region's `η`, `lighting` the estimated light (its
/// first convex/concave member).
pub(super) fn oriented_rows(
    domain: &Domain,
    input: &Input,
    confidence: &Image<f32>,
    theta: &Image<f32>,
    lighting: &Lighting,
    free: f64,
) -> Option<RelativePrior> {
    if free <= 0.0 {
        return None;
    }
    let conf: Vec<f64> = (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            if *input.unlit.get(x, y) {
                0.0
            } else {
                f64::from(*confidence.get(x, y))
            }
        })
        .collect();
    if conf.iter().all(|&c| c <= 0.0) {
        return None;
    }
    let aop: Vec<f64> = domain
        .gather(&input.aop)
        .into_iter()
        .map(f64::from)
        .collect();
    // A pair's strength: the AoP's confidence times the slope it is the
    // direction of (sin θ): where the gradient vanishes (a peak, a pit)
    // its direction turns at once, and continuity holds only around it.
    let strength: Vec<f64> = (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            conf[k] * f64::from(*theta.get(x, y)).sin()
        })
        .collect();
    let mut forest = ParityUnion::new(domain.len());
    for (_, k, j, across) in pairs_by_strength(domain, &aop, &strength) {
        forest.join(k, j, across);
    }
    // Per tree: its root and each member's parity, then the shading
    // evidence summed in the root's sense.
    let members: Vec<(usize, bool)> = (0..domain.len()).map(|k| forest.find(k)).collect();
    let evidence = pixel_evidence(domain, input, &aop, &conf, theta, lighting);
    let mut shading = vec![0.0; domain.len()];
    for (&(root, turned), e) in members.iter().zip(evidence) {
        shading[root] += if turned { -e } else { e };
    }
    let tied = members.iter().any(|&(root, _)| shading[root] == 0.0);
    let convex = if tied {
        bends_outward(domain, input, &aop, &conf, &members)
    } else {
        Vec::new()
    };
    let azimuth = members
        .iter()
        .zip(&aop)
        .map(|(&(root, turned), &a)| {
            let e = shading[root];
            let positive = if e == 0.0 { convex[root] } else { e > 0.0 };
            if turned == positive {
                a + std::f64::consts::PI
            } else {
                a
            }
        })
        .collect();
    Some(RelativePrior {
        azimuth,
        weight: conf.iter().map(|c| c * free).collect(),
    })
}

/// Each unknown's shading evidence for its AoP taken as it is (`ψ`, not
/// `ψ + π`): the squared miss of the opposite sense minus that of this one,
/// `4 r (st L_xy·ψ̂)` with `r` the intensity left after the ambient and
/// `ct L_z`, weighted by the AoP's confidence.
fn pixel_evidence(
    domain: &Domain,
    input: &Input,
    aop: &[f64],
    conf: &[f64],
    theta: &Image<f32>,
    lighting: &Lighting,
) -> Vec<f64> {
    let [lx, ly, lz] = lighting.vector;
    (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            if conf[k] <= 0.0 || *input.dark.get(x, y) {
                return 0.0;
            }
            let (st, ct) = f64::from(*theta.get(x, y)).sin_cos();
            let (sa, ca) = aop[k].sin_cos();
            let along = st * (ca * lx + sa * ly);
            let rest = f64::from(*input.intensity.get(x, y)) / input.intensity_scale
                - lighting.ambient
                - ct * lz;
            4.0 * conf[k] * along * rest
        })
        .collect()
}

/// The pairs of 4-neighbour unknowns, strongest first: `(weight, k, j,
/// across)`, `across` when `j`'s AoP must turn by π to continue `k`'s.
fn pairs_by_strength(
    domain: &Domain,
    aop: &[f64],
    strength: &[f64],
) -> Vec<(f64, usize, usize, bool)> {
    let mut pairs = Vec::with_capacity(2 * domain.len());
    for k in 0..domain.len() {
        let (x, y) = domain.pixel(k);
        let (x, y) = (x as isize, y as isize);
        for j in [domain.at(x + 1, y), domain.at(x, y + 1)]
            .into_iter()
            .flatten()
        {
            let c = (aop[k] - aop[j]).cos();
            pairs.push((strength[k].min(strength[j]) * c.abs(), k, j, c < 0.0));
        }
    }
    // Equal weights in unknown order, so the forest does not depend on the
    // sort's stability.
    pairs.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    pairs
}

/// Per root of the trees `members` (each unknown's root and parity): whether
/// its sense (its root's AoP as it is) bends away from the camera towards
/// the region's outline, the tie-break where the shading has no say (a
/// light along the view).
fn bends_outward(
    domain: &Domain,
    input: &Input,
    aop: &[f64],
    conf: &[f64],
    members: &[(usize, bool)],
) -> Vec<bool> {
    let outline = convexity_prior(&input.mask, 1.0);
    let mut bend = vec![0.0; domain.len()];
    for (k, &(root, turned)) in members.iter().enumerate() {
        let (x, y) = domain.pixel(k);
        let outward = f64::from(*outline.azimuth.get(x, y));
        let agree = conf[k] * f64::from(*outline.weight.get(x, y)) * (aop[k] - outward).cos();
        bend[root] += if turned { -agree } else { agree };
    }
    bend.iter().map(|&b| b >= 0.0).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::smsfp::Smsfp;
    use crate::test_support::mae;
    use sfp_core::Mask;
    use sfp_core::analytic::{AnalyticScene, Shape};

    /// The analytic blobs under a light along the view: no contour holds
    /// the relief and the shading rows are blind to the sense, so without
    /// the oriented rows the solved surface is flat (22.7° at 128²).
    #[test]
    fn a_relief_without_contours_under_a_frontal_light_keeps_its_shape() {
        let view = AnalyticScene {
            shape: Shape::Blobs,
            size: 96,
            light: [0.0, 0.0, 1.0],
            ..AnalyticScene::default()
        }
        .render()
        .unwrap();
        let input = Input::from_view(&view.input).unwrap();
        let gt = view.gt.unwrap().normals;
        let solved = Smsfp {
            per_pixel: false,
            ..Smsfp::default()
        };
        let (surface, _) = mae(&solved, &input, &gt);
        let (per_pixel, _) = mae(&Smsfp::default(), &input, &gt);
        println!("blobs 96², frontal light: solved {surface:.2}°, per pixel {per_pixel:.2}°");
        assert!(surface < 1.0, "solved surface {surface}°");
        assert!(per_pixel < 1.0, "per-pixel normals {per_pixel}°");
    }

    /// A radial AoP field (a bump, or a dip) with every other column's AoP
    /// given as its opposite direction: the forest orients all of it one
    /// way around the centre, which has no strength (the gradient vanishes
    /// there).
    #[test]
    fn the_forest_orients_a_line_field_by_continuity() {
        let mask = Mask::new(9, 9, true);
        let domain = Domain::new(&mask);
        let centre = |k: usize| {
            let (x, y) = domain.pixel(k);
            (y as f64 - 4.0).atan2(x as f64 - 4.0)
        };
        let aop: Vec<f64> = (0..domain.len())
            .map(|k| {
                let (x, _) = domain.pixel(k);
                centre(k)
                    + if x % 2 == 0 {
                        std::f64::consts::PI
                    } else {
                        0.0
                    }
            })
            .collect();
        let conf: Vec<f64> = (0..domain.len())
            .map(|k| if domain.pixel(k) == (4, 4) { 0.0 } else { 1.0 })
            .collect();
        let mut forest = ParityUnion::new(domain.len());
        for (_, k, j, across) in pairs_by_strength(&domain, &aop, &conf) {
            forest.join(k, j, across);
        }
        let senses: Vec<f64> = (0..domain.len())
            .filter(|&k| domain.pixel(k) != (4, 4))
            .map(|k| {
                let a = if forest.find(k).1 {
                    aop[k] + std::f64::consts::PI
                } else {
                    aop[k]
                };
                (a - centre(k)).cos().round()
            })
            .collect();
        assert!(senses.iter().all(|&s| s == senses[0]), "{senses:?}");
        assert_eq!(senses.len(), 80);
    }
}
