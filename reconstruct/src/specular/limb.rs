//! Which way the polarization lies along the occluding contour: a sign,
//! from the data alone, that a view's polarization is specular.
//!
//! At an occluding contour the surface is seen at grazing incidence. There
//! diffuse polarization is at its strongest (the diffuse DoP grows towards
//! 90° zenith) and lies across the outline: its AoP is the normal's
//! azimuth, the outline's outward direction (conventions.md §3). Specular
//! reflection lies along the outline (`ψ ≡ φ + π/2`). So, over a band of
//! [`LIMB_WIDTH`] pixels inside the outline, the DoP-weighted mean of
//! `cos 2(ψ − φ_out)` (`alignment`) is near +1 on a diffuse object and
//! below 0 where specular reflection outweighs the diffuse polarization at
//! the limb, which the diffuse model cannot produce.
//!
//! Two things make an alignment near 0 meaningless. Where the outline is
//! no occluding contour (a relief whose rim is a crease), the band is
//! nearly unpolarized and its AoP is noise. And one polarization direction
//! over the whole band (a polarized light, or a compact one reflected by
//! rough facets) gives an alignment as large as the band's outline
//! directions are unbalanced: `|Σ w e^{2iφ_out}| / Σ w` (`one_direction`;
//! 0 around a closed outline evenly weighted, up to 1 on a straight edge or
//! where shadow hides part of the outline). So the limb reads as specular
//! only when its alignment is below `−one_direction` by more than
//! [`SIGNIFICANCE`] standard errors of an AoP unrelated to the outline
//! (`cos 2Δ` of a uniform angle has variance ½: `sqrt(½ Σw²) / Σw`).
//!
//! Measured at 256² (`reports/glossy.md`, "The limb's polarization"):
//! every occluding limb of `builtin`, `a` and `b` has alignment 0.71–0.99,
//! their reliefs (`bumps`) 0.16 and 0.19, `a`'s camera 0.14; the glossy
//! preset's three draws run from −0.94 to +0.99.

use crate::input::Input;
use crate::prior::ConvexityPrior;
use serde::{Deserialize, Serialize};

/// Width of the band inside the outline (pixels): the steepest part of
/// any object more than a few pixels across, where a diffuse limb is most
/// polarized.
pub const LIMB_WIDTH: f32 = 3.0;
/// Standard errors below `−one_direction` at which the alignment says
/// "specular".
pub const SIGNIFICANCE: f64 = 3.0;

/// The limb's polarization (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Limb {
    /// DoP-weighted mean of `cos 2(ψ − φ_out)` over the band: +1 across
    /// the outline (diffuse), −1 along it (specular).
    pub alignment: f64,
    /// The largest |alignment| one polarization direction gives this band.
    pub one_direction: f64,
    /// Standard error of the alignment for an AoP unrelated to the outline.
    pub standard_error: f64,
    /// Band pixels counted.
    pub pixels: usize,
}

impl Limb {
    /// The limb of `input`'s mask (AoPs as measured) by `prior`'s outline
    /// (exponent `DEFAULT_EXPONENT`), or `None` without an occluding
    /// outline or any polarization there. Unlit and clipped pixels are left
    /// out: their AoP is meaningless.
    pub fn of(input: &Input, prior: &ConvexityPrior) -> Option<Limb> {
        let (mut along, mut weights, mut squares, mut pixels) = (0.0, 0.0, 0.0, 0);
        let mut directions = [0.0; 2];
        for i in 0..input.mask.len() {
            let counted = input.mask.data()[i]
                && !input.unlit.data()[i]
                && !input.saturated.data()[i]
                && prior.weight.data()[i] > 0.0
                && prior.distance.data()[i] < LIMB_WIDTH;
            if !counted {
                continue;
            }
            let w = f64::from(input.dop.data()[i]);
            let outward = 2.0 * f64::from(prior.azimuth.data()[i]);
            along += w * (2.0 * f64::from(input.aop.data()[i]) - outward).cos();
            directions[0] += w * outward.cos();
            directions[1] += w * outward.sin();
            weights += w;
            squares += w * w;
            pixels += 1;
        }
        (weights > 0.0).then(|| Limb {
            alignment: along / weights,
            one_direction: directions[0].hypot(directions[1]) / weights,
            standard_error: (0.5 * squares).sqrt() / weights,
            pixels,
        })
    }

    /// Whether the limb is polarized along the outline beyond what noise
    /// or one polarization direction explains: specular reflection.
    pub fn is_specular(&self) -> bool {
        self.alignment + self.one_direction + SIGNIFICANCE * self.standard_error < 0.0
    }

    /// What `sfp import` says of a specular limb, and what to do.
    pub fn warning(&self) -> String {
        format!(
            "the occluding contour is polarized along the outline (alignment {:.2} over {} \
             pixels; diffuse polarization lies across it): specular reflection there, which \
             every method but SMSfP's default reads as diffuse; reconstruct with smsfp, \
             or with --set specular=auto",
            self.alignment, self.pixels
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prior::{DEFAULT_EXPONENT, convexity_prior};
    use crate::specular::fit::MixedFit;
    use crate::test_support::analytic;
    use sfp_core::analytic::Shape;
    use std::f32::consts::{FRAC_PI_2, PI};

    fn limb_of(input: &Input) -> Option<Limb> {
        Limb::of(input, &convexity_prior(&input.mask, DEFAULT_EXPONENT))
    }

    /// The analytic sphere (diffuse) and the same DoPs with every AoP
    /// turned by 90° (specular reflection).
    fn spheres() -> (Input, Input) {
        let (diffuse, _) = analytic(Shape::Sphere, 64, 1.5);
        let mut turned = diffuse.clone();
        for a in turned.aop.data_mut() {
            *a = (*a + FRAC_PI_2) % PI;
        }
        (diffuse, turned)
    }

    #[test]
    fn a_diffuse_limb_lies_across_the_outline_and_a_specular_one_along_it() {
        let (diffuse, turned) = spheres();
        let limb = limb_of(&diffuse).unwrap();
        assert!(limb.alignment > 0.9 && !limb.is_specular(), "{limb:?}");
        let limb = limb_of(&turned).unwrap();
        assert!(limb.alignment < -0.9 && limb.is_specular(), "{limb:?}");
        // One polarization direction over the whole band, whichever, is no
        // evidence either way: part of this limb is unlit, so its outline
        // directions are unbalanced and the alignment is not 0, but never
        // beyond what one direction can give.
        for k in 0..12 {
            let mut one = diffuse.clone();
            one.aop.data_mut().fill(k as f32 * PI / 12.0);
            let limb = limb_of(&one).unwrap();
            assert!(limb.one_direction > 0.05, "{limb:?}");
            assert!(
                limb.alignment.abs() <= limb.one_direction + 1e-9,
                "{limb:?}"
            );
            assert!(!limb.is_specular(), "{limb:?}");
        }
    }

    #[test]
    fn auto_fits_the_mixed_model_where_the_limb_is_specular() {
        let (diffuse, turned) = spheres();
        let (across, along) = (limb_of(&diffuse), limb_of(&turned));
        // With the η search inside its range (or no search), the limb decides.
        for search in [Some(false), None] {
            assert!(!MixedFit::Auto.decide(search, across.as_ref(), None).0);
            let (mixed, why) = MixedFit::Auto.decide(search, along.as_ref(), None);
            assert!(mixed && why.contains("occluding contour"), "{why}");
            // Without an outline nothing is read from it.
            assert!(!MixedFit::Auto.decide(search, None, None).0);
        }
        // The search at its end decides alone; the switches override both.
        assert!(MixedFit::Auto.decide(Some(true), across.as_ref(), None).0);
        assert!(!MixedFit::Off.decide(Some(true), along.as_ref(), None).0);
        assert!(MixedFit::On.decide(Some(false), across.as_ref(), None).0);
    }
}
