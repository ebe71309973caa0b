//! How much of a mask the diffuse model cannot explain: the warning
//! `sfp import` and `sfp reconstruct` give for glossy objects (the issue on
//! mixed specular/diffuse polarization, item 5), from the data alone.
//!
//! Diffuse polarization is weak away from the occluding contour: on a
//! convex object, a pixel further inside than a quarter of the mask's
//! largest inner distance has a zenith below about 49° (a sphere's, the
//! steepest convex profile), where the diffuse DoP stays under 0.06 for
//! η = 1.5. Specular reflection polarizes strongly there (0.3–0.9 below
//! Brewster's angle). So an interior pixel whose DoP, less twice its noise,
//! exceeds the diffuse DoP at a 60° zenith for η = 1.5 ([`CEILING_ZENITH`],
//! 0.096: a margin for flatter shapes and larger η) is read as not diffuse.
//! A large share of such pixels means the methods, which read every pixel
//! as diffuse unless `specular` says otherwise, will be wrong there.

use crate::input::Input;
use crate::noise::{dop_snr, stokes_noise};
use crate::prior::{DEFAULT_EXPONENT, convexity_prior};
use serde::{Deserialize, Serialize};
use sfp_core::fresnel::diffuse_dop;

/// Zenith whose diffuse DoP at [`CEILING_ETA`] bounds an interior pixel's.
const CEILING_ZENITH_DEG: f64 = 60.0;
const CEILING_ETA: f64 = 1.5;
/// Pixels further from the outline than this share of the mask's largest
/// inner distance are interior.
const INTERIOR: f32 = 0.25;
/// Share of the mask above which the commands warn.
pub const WARN_SHARE: f64 = 0.05;

/// Mask pixels the diffuse model cannot explain.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BeyondDiffuse {
    /// Interior pixels polarized beyond the diffuse ceiling.
    pub pixels: usize,
    /// Their share of the mask.
    pub share: f64,
    /// The DoP ceiling used.
    pub dop_ceiling: f64,
}

impl BeyondDiffuse {
    /// The figures of `input` (rule of the module doc).
    pub fn of(input: &Input) -> BeyondDiffuse {
        let ceiling = diffuse_dop(CEILING_ZENITH_DEG.to_radians(), CEILING_ETA);
        let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
        let deepest = prior.distance.data().iter().copied().fold(0.0f32, f32::max);
        let snr = dop_snr(input, &stokes_noise(input));
        let pixels = (0..input.mask.len())
            .filter(|&i| input.mask.data()[i] && !input.dark.data()[i])
            .filter(|&i| prior.distance.data()[i] > INTERIOR * deepest)
            .filter(|&i| {
                let (rho, snr) = (f64::from(input.dop.data()[i]), f64::from(snr.data()[i]));
                // ρ − 2σ with σ = ρ / SNR.
                snr > 2.0 && rho * (1.0 - 2.0 / snr) > ceiling
            })
            .count();
        BeyondDiffuse {
            pixels,
            share: pixels as f64 / input.mask.count().max(1) as f64,
            dop_ceiling: ceiling,
        }
    }

    /// The warning for a share of at least [`WARN_SHARE`], saying what to do.
    pub fn warning(&self) -> Option<String> {
        (self.share >= WARN_SHARE).then(|| {
            format!(
                "{:.0}% of the mask ({} pixels) is polarized more than diffuse reflection \
                 polarizes there (DoP above {:.3} away from the outline): specular reflection, \
                 which the methods read as diffuse unless told otherwise; reconstruct with \
                 --set specular=auto, or --set specular=MASK.png to name the glossy pixels",
                100.0 * self.share,
                self.pixels,
                self.dop_ceiling
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::analytic::{AnalyticScene, Shape};
    use sfp_core::fresnel::specular_dop;

    fn sphere() -> Input {
        let view = AnalyticScene {
            shape: Shape::Sphere,
            size: 64,
            light: [0.3, 0.2, 1.0],
            ..AnalyticScene::default()
        }
        .render()
        .unwrap();
        Input::from_view(&view.input).unwrap()
    }

    #[test]
    fn a_diffuse_sphere_is_explained_and_a_glossy_patch_is_not() {
        let input = sphere();
        let clean = BeyondDiffuse::of(&input);
        assert_eq!(clean.pixels, 0, "{clean:?}");
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
        assert_eq!(found.pixels, patch, "{found:?}");
        let warning = found.warning().unwrap();
        assert!(warning.contains("specular=auto"), "{warning}");
    }
}
