//! The specular share of each pixel's intensity, from its polarization and
//! a surface normal (issue: mixed specular/diffuse polarization, item 2).
//!
//! With a share `f` of `s0` reflected at the surface and the rest
//! transmitted out of it, the polarization measured along the normal's
//! azimuth `φ` is `q = ρ cos 2(ψ − φ) = (1 − f) ρ_d(θ) − f ρ_s(θ)`
//! (`model.rs`), so `f = (ρ_d(θ) − q) / (ρ_d(θ) + ρ_s(θ))`. `q` is the
//! same for `φ` and `φ + π`: the normal's sense does not matter, only its
//! zenith and the axis of its azimuth. Which AoPs are turned by 90° (the
//! specular part's polarization outweighs the diffuse part's) and which
//! pixels are highlights (its share of `s0` outweighs the diffuse part's)
//! are different sets: on preset `b --svbrdf` at 512² the turned AoPs are
//! 6–38% of an object's pixels, the highlights 16 pixels on the dog and
//! 8,453 on the mug (its inner wall, seen at 74–85° zenith).

use crate::input::Input;
use crate::normal::normal_azimuth;
use sfp_core::fresnel::{diffuse_dop, specular_dop};
use sfp_core::labelling::SpecularScores;
use sfp_core::view::GroundTruth;
use sfp_core::{Image, Mask};

/// Largest zenith the share is read at: at 90° both DoPs vanish.
const MAX_ZENITH_DEG: f64 = 89.0;

/// What a method read as specular with its `specular` option on.
#[derive(Clone, Debug)]
pub struct SpecularReading {
    /// Pixels whose AoP the method turned by 90° (`specular.png`; the
    /// polarization class of `metrics.json`).
    pub turned: Mask,
    /// Specular share of `s0` per mask pixel, in `[0, 1]`, from the
    /// method's output normals (`specular.exr`; above ½: the intensity
    /// class of `metrics.json`).
    pub share: Image<f32>,
}

impl SpecularReading {
    /// The reading of `turned` pixels with the share of `input` (as
    /// measured, AoPs not turned) under `normals` at refractive index `eta`.
    pub fn new(turned: Mask, input: &Input, normals: &Image<[f32; 3]>, eta: f64) -> Self {
        SpecularReading {
            turned,
            share: specular_share(input, normals, eta),
        }
    }

    /// Pixels where the specular part outweighs the diffuse part in `s0`.
    pub fn highlights(&self) -> Mask {
        self.share.map(|&f| f > 0.5)
    }

    /// The turned pixels and the highlights scored over `mask` against the
    /// mixture of `gt` (`metrics.json`'s `specular`); `None` without it.
    pub fn scores(&self, gt: &GroundTruth, mask: &Mask) -> Option<SpecularScores> {
        gt.specular_scores(&self.turned, &self.highlights(), mask)
    }
}

/// The specular share `f` of every mask pixel under `normals` (camera
/// frame), clamped to `[0, 1]`; 0 outside the mask, where a normal is
/// missing (all zero or not finite) or faces away from the camera, and
/// where it faces the camera exactly.
pub fn specular_share(input: &Input, normals: &Image<[f32; 3]>, eta: f64) -> Image<f32> {
    let (w, h) = input.size();
    let max_zenith = MAX_ZENITH_DEG.to_radians();
    Image::from_fn(w, h, |x, y| {
        let n = *normals.get(x, y);
        let phi = normal_azimuth(n);
        let nz = f64::from(n[2]);
        if !(*input.mask.get(x, y) && nz > 0.0 && phi.is_finite()) {
            return 0.0;
        }
        let theta = nz.min(1.0).acos().min(max_zenith);
        let rho = f64::from(*input.dop.get(x, y));
        let psi = f64::from(*input.aop.get(x, y));
        let q = rho * (2.0 * (psi - phi)).cos();
        let (d, s) = (diffuse_dop(theta, eta), specular_dop(theta, eta));
        share_along(q, d, s).map_or(0.0, |f| f.clamp(0.0, 1.0) as f32)
    })
}

/// The specular share, not clamped, that gives the polarization `q` along
/// a normal's azimuth where the diffuse and specular DoPs are `d` and `s`.
/// `None` facing the camera, where both parts are unpolarized: nothing
/// tells them apart (and 0/0 would be NaN).
pub fn share_along(q: f64, d: f64, s: f64) -> Option<f64> {
    (d + s > 0.0).then(|| (d - q) / (d + s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::mixture;
    use std::f64::consts::FRAC_PI_2;

    /// Largest `|found − share(x)|` where the zenith is between 3° and 87°
    /// (both DoPs vanish at 0° and the share is not observable there).
    fn worst(found: &Image<f32>, normals: &Image<[f32; 3]>, share: impl Fn(usize) -> f64) -> f64 {
        let (w, h) = found.size();
        let mut worst: f64 = 0.0;
        for y in 0..h {
            for x in 0..w {
                let nz = f64::from(normals.get(x, y)[2]);
                if nz > 87f64.to_radians().cos() && nz < 3f64.to_radians().cos() {
                    worst = worst.max((f64::from(*found.get(x, y)) - share(x)).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn the_share_of_a_known_mixture_is_recovered_everywhere() {
        // Left half 20% specular (AoP along the azimuth below Brewster's
        // angle's neighbourhood, turned where ρ_s wins), right half 70%.
        let share = |x: usize| if x < 32 { 0.2 } else { 0.7 };
        let (input, normals) = mixture(1.5, share);
        let found = specular_share(&input, &normals, 1.5);
        let err = worst(&found, &normals, share);
        assert!(err < 1e-3, "largest share error {err}");
        let reading = SpecularReading::new(Mask::new(64, 64, false), &input, &normals, 1.5);
        let highlights = reading.highlights();
        assert!(*highlights.get(44, 32) && !*highlights.get(20, 32));
        assert_eq!(*found.get(0, 0), 0.0, "outside the mask");
        // A method without a normal at a pixel: no share, not NaN.
        let mut holes = normals.clone();
        *holes.get_mut(44, 32) = [f32::NAN; 3];
        *holes.get_mut(20, 32) = [0.0; 3];
        // Facing the camera exactly both DoPs are 0 and the share is
        // unobservable, whatever was measured: no DoP (0/0), or a DoP across
        // the azimuth (q < 0: −q/0 would read fully specular).
        let mut input = input;
        *holes.get_mut(32, 20) = [0.0, 0.0, 1.0];
        *input.dop.get_mut(32, 20) = 0.0;
        *holes.get_mut(33, 20) = [0.0, 0.0, 1.0];
        *input.dop.get_mut(33, 20) = 0.05;
        *input.aop.get_mut(33, 20) = FRAC_PI_2 as f32;
        let found = specular_share(&input, &holes, 1.5);
        let at = |x, y| *found.get(x, y);
        assert_eq!([at(44, 32), at(20, 32), at(32, 20), at(33, 20)], [0.0; 4]);
    }

    #[test]
    fn a_diffuse_surface_has_no_specular_share() {
        let (input, normals) = mixture(1.3, |_| 0.0);
        let found = specular_share(&input, &normals, 1.3);
        let err = worst(&found, &normals, |_| 0.0);
        assert!(err < 1e-3, "largest share {err}");
    }
}
