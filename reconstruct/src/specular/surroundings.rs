//! The intensity at which a glossy object's specular reflection of its
//! surroundings cancels its diffuse polarization (README, "Specular
//! reflection"; `reports/specular.md` has the measurements).
//!
//! A pixel of diffuse radiance `I_d` that also reflects unpolarized
//! surroundings of radiance `L` (the specular weight included) polarizes
//! along its azimuth by `q = I_d ρ_d(θ) − L (R_s − R_p)/2`. Diffuse light
//! leaves through Fresnel transmission, so `ρ_d = (R_s − R_p)/(2 − R_s − R_p)`
//! (conventions.md §3) and, with `s = I_d + L (R_s + R_p)/2` the pixel's
//! intensity,
//!
//! `q = ρ_d(θ) (s − L)` at every zenith and every η:
//!
//! the AoP is turned by 90° exactly where the pixel is darker than `L`.
//! Surroundings of even radiance are the idealisation; on preset
//! `b --svbrdf` the rule with the rendered `L` labels the mug's turned
//! pixels with F1 0.81 but not the rough, concave dog's (0.05), whose
//! grazing reflection is shadowed. So `L` is estimated per view, and only
//! kept where the data show it.

use crate::input::Input;
use crate::prior::ConvexityPrior;

/// Least gain of the estimate over no threshold, in units of the root sum
/// of squares of the boundary's evidence. Were intensity unrelated to the
/// sense, the gain would be the largest prefix sum of a walk of steps
/// `±2 × evidence`, which by the reflection principle exceeds 1.5 of its σ
/// (this bound) with probability ≈ 0.13 if it has no drift; the boundary's
/// evidence is mostly diffuse, so the walk drifts down and a chance gain is
/// rarer. Measured on the diffuse presets: no view reaches it (largest 1.02,
/// the built-in bumps, whose outline is no occluding contour); on the
/// SVBRDF views the mugs reach 3.6–21.5 and the beetle car 7.9, the camera
/// 1.6 (`reports/specular.md`).
const MIN_SIGNIFICANCE: f64 = 3.0;

/// One occluding-boundary pixel: its intensity and its signed evidence,
/// positive when its AoP points outwards (diffuse sense).
struct Evidence {
    intensity: f32,
    outward: f64,
}

/// The radiance `L` of the reflected surroundings (module doc), in the
/// input's intensity units, or `None` when the data do not show one.
///
/// Along the occluding boundary the azimuth points outwards, so a pixel's
/// AoP says whether it is turned. Sorted by intensity, the threshold is the
/// one below which the pixels read most as turned and above which most as
/// diffuse: the largest prefix sum of the turned evidence. `pixels` are
/// the boundary pixels whose DoP is clear of its noise, each with the
/// weight the caller gives its AoP.
pub fn estimate(
    input: &Input,
    prior: &ConvexityPrior,
    pixels: impl Iterator<Item = (usize, f64)>,
) -> Option<f32> {
    let w = input.size().0;
    let mut evidence: Vec<Evidence> = pixels
        .map(|(i, weight)| {
            let (x, y) = (i % w, i / w);
            let outward = f64::from(*prior.azimuth.get(x, y));
            let agree = (2.0 * (f64::from(input.aop.data()[i]) - outward)).cos();
            Evidence {
                intensity: input.intensity.data()[i],
                outward: weight * agree,
            }
        })
        .collect();
    evidence.sort_unstable_by(|a, b| a.intensity.total_cmp(&b.intensity));
    let spread = evidence
        .iter()
        .map(|e| e.outward * e.outward)
        .sum::<f64>()
        .sqrt();
    let (mut gain, mut best, mut below) = (0.0, 0.0, None);
    for (k, e) in evidence.iter().enumerate() {
        // Reading this pixel as turned instead of diffuse.
        gain -= 2.0 * e.outward;
        if gain > best {
            best = gain;
            below = Some(k);
        }
    }
    let k = below?;
    if best < MIN_SIGNIFICANCE * spread {
        return None;
    }
    let next = evidence
        .get(k + 1)
        .map_or(evidence[k].intensity, |e| e.intensity);
    Some(0.5 * (evidence[k].intensity + next))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::{dop_snr, stokes_noise};
    use crate::prior::{DEFAULT_EXPONENT, convexity_prior};
    use crate::specular::model::boundary_evidence as evidence;
    use crate::test_support::glossy_sphere;
    use sfp_core::fresnel::{diffuse_dop, reflectance};

    #[test]
    fn the_turning_intensity_is_the_surroundings_radiance() {
        for eta in [1.3, 1.5, 1.8] {
            for deg in (1..90).step_by(4) {
                let theta = f64::from(deg).to_radians();
                let (rs, rp) = reflectance(theta.cos(), eta);
                for (diffuse, surroundings) in [(0.3, 0.1), (0.05, 0.2), (1.0, 1.0)] {
                    let q = diffuse * diffuse_dop(theta, eta) - surroundings * (rs - rp) / 2.0;
                    let s = diffuse + surroundings * (rs + rp) / 2.0;
                    let identity = diffuse_dop(theta, eta) * (s - surroundings);
                    assert!((q - identity).abs() < 1e-12, "η {eta}, θ {deg}°");
                }
            }
        }
    }

    /// With the weights `specular = "auto"` gives the evidence. At 64² the
    /// weakest surroundings (0.05) gain 2.96 root sums of squares, just below
    /// [`MIN_SIGNIFICANCE`]: the bar grows with the square root of the
    /// boundary's length, the gain with its length; 96² gains 4.7.
    #[test]
    fn a_glossy_sphere_shows_its_surroundings_and_a_matte_one_none() {
        for surroundings in [0.05, 0.1, 0.2] {
            let (input, truth) = glossy_sphere(96, surroundings);
            let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
            let snr = dop_snr(&input, &stokes_noise(&input));
            let found =
                estimate(&input, &prior, evidence(&input, &prior, &snr)).expect("a threshold");
            assert!(
                (found / truth - 1.0).abs() < 0.1,
                "{surroundings}: {found} for {truth}"
            );
        }
        let (matte, _) = glossy_sphere(96, 0.0);
        let prior = convexity_prior(&matte.mask, DEFAULT_EXPONENT);
        let snr = dop_snr(&matte, &stokes_noise(&matte));
        assert_eq!(
            estimate(&matte, &prior, evidence(&matte, &prior, &snr)),
            None
        );
    }
}
