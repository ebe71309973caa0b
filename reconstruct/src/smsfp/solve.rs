//! Step 7 of SMSfP (module doc): the per-region solves of the shared
//! height-from-polarization system (`system`, Eq. 18), in parallel over
//! regions, each on its window, and the one choice of light for the whole
//! object.
//!
//! The convex/concave light pair is decided once for the whole object: both
//! members are solved per region (one factorisation), their normals stitched,
//! and the member whose stitched normals agree better with the outward
//! directions of the mask's trusted occluding contours (step 4; the whole
//! mask boundary when none is trusted) is kept everywhere. A boundary that
//! only cuts the surface (an open shell's rim, a mask edge facing the camera)
//! says nothing about the sense and outvoted the limb on a cut sphere (test
//! `light_is_chosen_on_occluding_contours_only`: 66.5° → 1.2°).

use super::region::RegionState;
use super::stitch::stitch;
use crate::input::Input;
use crate::light::Lighting;
use crate::prior::{convexity_prior, convexity_prior_trusted};
use crate::solver::domain::Domain;
use crate::system::{PixelData, System, agreement_band, boundary_agreement};
use rayon::prelude::*;
use sfp_core::{Mask, Result};

/// The light kept for the whole object (step 7).
pub(super) struct LightChoice {
    /// The kept member of the pair.
    pub lighting: Lighting,
    /// Index of the kept member: 0 the estimate, 1 its flipped partner.
    pub chosen: usize,
    /// Each member's agreement with the contours (empty when the light is
    /// not ambiguous).
    pub scores: Vec<f64>,
}

/// Solves region `s` for `lighting` (both members when `ambiguous`), with
/// the region's current `η` and `α` and smoothness weight `lambda`.
pub(super) fn solve_region(
    s: &mut RegionState,
    lighting: &Lighting,
    ambiguous: bool,
    lambda: f64,
) -> Result<()> {
    let (theta, clamped) = s.input.zenith(s.eta);
    s.clamped = clamped;
    let mut data = PixelData::gather(&s.domain, &s.input, &theta, None)?;
    s.theta = theta;
    data.intensity.iter_mut().for_each(|v| *v /= s.alpha);
    data.azimuth_weight.clone_from(&s.azimuth_weight);
    let system = System {
        domain: &s.domain,
        data: &data,
        prior: &s.prior,
        lambda,
        relative: s.relative.as_ref(),
    };
    s.solved = Some(system.solve(&mut s.solver, lighting, ambiguous)?);
    s.iterations += 1;
    Ok(())
}

/// The first solves of every region with `lighting` (both members when
/// `ambiguous`) and the member kept for all, judged on the contours
/// `trusted` of `input`'s mask with the prior's exponent `prior_exponent`;
/// each region keeps that member's heights and normals.
pub(super) fn solve_regions(
    states: &mut [RegionState],
    input: &Input,
    trusted: &Mask,
    lighting: Lighting,
    ambiguous: bool,
    lambda: f64,
    prior_exponent: f64,
) -> Result<LightChoice> {
    let (w, h) = input.size();
    states
        .par_iter_mut()
        .try_for_each(|s| solve_region(s, &lighting, ambiguous, lambda))?;
    let mut scores = Vec::new();
    let chosen = if ambiguous {
        let whole = Domain::new(&input.mask);
        let contour =
            convexity_prior_trusted(&input.mask, prior_exponent, |x, y, _| *trusted.get(x, y));
        let prior = if contour.weight.data().iter().any(|&w| w > 0.0) {
            contour
        } else {
            convexity_prior(&input.mask, prior_exponent)
        };
        let band = agreement_band(&whole, &prior);
        for c in 0..2 {
            let normals = stitch(states, w, h, |s| {
                &s.solved.as_ref().expect("solved").candidates[c].normals
            });
            scores.push(boundary_agreement(
                &whole,
                &whole.gather(&normals),
                &prior,
                band,
            ));
        }
        usize::from(scores[1] > scores[0])
    } else {
        0
    };
    for s in states.iter_mut() {
        let kept = s
            .solved
            .take()
            .expect("solved")
            .candidates
            .swap_remove(chosen);
        s.z = kept.z;
        s.normals = kept.normals;
        if chosen == 1
            && let Some(relative) = &mut s.relative
        {
            relative.turn();
        }
    }
    let lighting = if chosen == 1 {
        lighting.flipped()
    } else {
        lighting
    };
    Ok(LightChoice {
        lighting,
        chosen,
        scores,
    })
}

#[cfg(test)]
mod tests {
    use super::super::Smsfp;
    use crate::input::Input;
    use crate::method::Method;
    use crate::test_support::analytic;
    use sfp_core::Mask;
    use sfp_core::analytic::Shape;
    use sfp_core::metrics::evaluate;
    use sfp_core::stokes::Polarimetry;

    #[test]
    fn light_is_chosen_on_occluding_contours_only() {
        // The right part of a sphere, cut along n_x = 0.5: the cut is mask
        // boundary but no occluding contour (zenith 30° there), and its
        // outward direction opposes the normals. Only the limb may vote.
        let (full, gt) = analytic(Shape::Sphere, 96, 1.5);
        let mask = Mask::from_fn(96, 96, |x, y| {
            *full.mask.get(x, y) && gt.get(x, y)[0] >= 0.5
        });
        let pol = Polarimetry {
            intensity: full.intensity.clone(),
            dop: full.dop.clone(),
            aop: full.aop.clone(),
        };
        let input = Input::new(pol, Some(mask)).unwrap();
        let rec = Smsfp::default().reconstruct(&input).unwrap();
        let light = rec.run.light.unwrap();
        let (chosen, scores) = (light.chosen, light.boundary_agreement.unwrap());
        let m = evaluate(&rec.normals, &gt, &input.mask).unwrap();
        println!("scores {scores:?}, chosen {chosen}, MAE {}", m.mae_deg);
        assert!(scores[chosen] > 0.7, "agreement {scores:?}");
        assert!(m.mae_deg < 2.0, "MAE {}°", m.mae_deg);
    }
}
