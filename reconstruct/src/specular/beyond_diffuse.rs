//! How much of a mask the diffuse model cannot explain: the warning
//! `sfp import` and `sfp reconstruct` give for glossy objects (the issue on
//! mixed specular/diffuse polarization, item 5), from the data alone.
//!
//! Diffuse polarization is weak away from the occluding contour. At a
//! distance `d` inside an outline whose deepest inner point is `D` from
//! it, a sphere of radius `D` (the steepest convex profile) has the zenith
//! `asin(1 − d/D)`; the ceiling of the diffuse DoP there is the diffuse DoP
//! at that zenith, and never below its value at 60° ([`FLOOR_ZENITH_DEG`],
//! 0.096 for η = 1.5: a margin for flatter, slanted shapes). Specular
//! reflection polarizes strongly well inside the outline (0.3–0.9 below
//! Brewster's angle). A pixel whose DoP, less twice its noise, exceeds the
//! ceiling is polarized beyond the diffuse model. A large share of such
//! pixels means the methods, which read every pixel as diffuse unless
//! `specular` says otherwise, will be wrong there; `specular = "auto"`
//! counts each such pixel as a vote for its AoP being turned.

use crate::input::Input;
use crate::noise::{StokesNoise, dop_snr, stokes_noise};
use crate::prior::{ConvexityPrior, DEFAULT_EXPONENT, convexity_prior};
use serde::{Deserialize, Serialize};
use sfp_core::fresnel::diffuse_dop;

/// The ceiling's zenith is never below this.
const FLOOR_ZENITH_DEG: f64 = 60.0;
/// Refractive index of the import's check (no estimate there).
const CHECK_ETA: f64 = 1.5;
/// Share of the mask above which the commands warn.
pub const WARN_SHARE: f64 = 0.05;

/// The highest DoP diffuse reflection gives at distance `d` inside an
/// outline whose deepest inner distance is `deepest`, for refractive index
/// `eta` (module doc).
pub fn diffuse_ceiling(d: f64, deepest: f64, eta: f64) -> f64 {
    let sphere = (1.0 - d / deepest.max(1.0)).clamp(0.0, 1.0).asin();
    diffuse_dop(sphere.max(FLOOR_ZENITH_DEG.to_radians()), eta)
}

/// Whether a DoP `rho` measured with signal-to-noise ratio `snr` exceeds
/// `ceiling` by more than twice its noise (`σ = ρ / SNR`).
pub fn exceeds(rho: f64, snr: f64, ceiling: f64) -> bool {
    snr > 2.0 && rho * (1.0 - 2.0 / snr) > ceiling
}

/// Mask pixels the diffuse model cannot explain.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BeyondDiffuse {
    /// Pixels polarized beyond the diffuse ceiling.
    pub pixels: usize,
    /// Their share of the mask.
    pub share: f64,
}

impl BeyondDiffuse {
    /// The figures of `input` (rule of the module doc, η = 1.5).
    pub fn of(input: &Input) -> BeyondDiffuse {
        let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
        Self::with_prior(input, &prior, &stokes_noise(input))
    }

    /// [`BeyondDiffuse::of`] with the mask's convexity prior (exponent
    /// `DEFAULT_EXPONENT`) and its Stokes noise already at hand.
    pub fn with_prior(input: &Input, prior: &ConvexityPrior, noise: &StokesNoise) -> BeyondDiffuse {
        let deepest = prior.deepest();
        let snr = dop_snr(input, noise);
        let pixels = (0..input.mask.len())
            .filter(|&i| input.mask.data()[i] && !input.dark.data()[i])
            .filter(|&i| {
                let d = f64::from(prior.distance.data()[i]);
                let ceiling = diffuse_ceiling(d, f64::from(deepest), CHECK_ETA);
                exceeds(
                    f64::from(input.dop.data()[i]),
                    f64::from(snr.data()[i]),
                    ceiling,
                )
            })
            .count();
        BeyondDiffuse {
            pixels,
            share: pixels as f64 / input.mask.count().max(1) as f64,
        }
    }

    /// The warning for a share of at least [`WARN_SHARE`], saying what to do.
    pub fn warning(&self) -> Option<String> {
        (self.share >= WARN_SHARE).then(|| {
            format!(
                "{:.0}% of the mask ({} pixels) is polarized more than diffuse reflection \
                 polarizes at its distance from the outline: specular reflection, \
                 which the methods read as diffuse unless told otherwise; reconstruct with \
                 --set specular=auto, or --set specular=MASK.png to name the glossy pixels",
                100.0 * self.share,
                self.pixels
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::analytic;
    use sfp_core::analytic::Shape;
    use sfp_core::fresnel::specular_dop;

    fn sphere() -> Input {
        analytic(Shape::Sphere, 64, 1.5).0
    }

    #[test]
    fn a_diffuse_sphere_is_explained_and_a_glossy_patch_is_not() {
        let input = sphere();
        let clean = BeyondDiffuse::of(&input);
        // A few rim pixels, where the pixel grid's outline is not the
        // sphere's, and no warning.
        assert!(clean.share < 0.01, "{clean:?}");
        assert!(clean.warning().is_none());

        // A highlight: the centre's pixels polarized as specular reflection
        // at 30° (DoP ≈ 0.4 for η = 1.5).
        let (w, h) = input.size();
        let mut glossy = input.clone();
        let mut patch = 0;
        for y in 0..h {
            for x in 0..w {
                let r = (x as f64 + 0.5 - 32.0).hypot(y as f64 + 0.5 - 32.0);
                if r < 8.0 {
                    *glossy.dop.get_mut(x, y) = specular_dop(30f64.to_radians(), 1.5) as f32;
                    patch += 1;
                }
            }
        }
        let found = BeyondDiffuse::of(&glossy);
        assert_eq!(found.pixels, clean.pixels + patch, "{found:?}");
        let warning = found.warning().unwrap();
        assert!(warning.contains("specular=auto"), "{warning}");
    }
}
