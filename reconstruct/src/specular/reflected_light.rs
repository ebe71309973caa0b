//! A compact light reflected by rough microfacets, told from the data: the
//! sign that SMSfP's `reflected_light = "auto"` reads.
//!
//! On a rough surface the facets that reflect a compact light towards the
//! camera face half-way between the light and the view, whatever the
//! surface's own normal does. So that reflection is polarized in one
//! direction over the whole object, across the plane of the light and the
//! view. The mixed-model fit can model it (`fit::Model::reflected_light`).
//! But on the glossy preset the term, on for every view, costs 1.8°: its
//! per-window strength also takes up the reflection of the surroundings.
//! So it is turned on only where the data show such light.
//!
//! The sign is the net polarization `|Σ (s1, s2)| / Σ s0` over the deepest
//! tenth of the mask: the pixels whose distance from the outline is at or
//! above the 90th percentile. Reflection by the surface itself cannot give
//! much there, for two reasons:
//! - On a convex object the normals around its deepest point turn through
//!   every azimuth, so their polarizations cancel in the sum.
//! - Even if every pixel there were polarized one way, as strongly as
//!   reflection at its zenith allows, the net would stay below the
//!   specular DoP at the largest zenith of a sphere's deepest tenth,
//!   `asin √0.1 = 18.4°` (0.143 at η 1.5). That DoP is the `bound`.
//!
//! A net beyond the bound by more than [`SIGNIFICANCE`] standard errors of
//! the sensor noise is light that was polarized before the surface sent it
//! to the camera: a compact light off rough facets, or a polarized light.
//! A flat glossy face turned from the camera and seen whole would also
//! pass: its pixels share one azimuth. Nearest among the synthetic views
//! comes a body hidden in part by another, whose deepest tenth lies off its
//! pole: the glossy preset's `--seed 11` `snowman_1`, 0.122.
//!
//! Measured (`reports/glossy.md`, "A compact light reflected by rough
//! facets, from the data"): the glossy preset's three draws 0.000–0.122,
//! `builtin`, `a`, `b` and their `--svbrdf` variants at most 0.031, the
//! fruit capture 0.191.

use crate::input::Input;
use crate::noise::StokesNoise;
use crate::prior::ConvexityPrior;
use crate::switch::Switch;
use serde::{Deserialize, Serialize};
use sfp_core::fresnel::specular_dop;

/// Share of the mask, the deepest by distance from the outline, whose net
/// polarization is read.
pub const DEEPEST_SHARE: f64 = 0.1;
/// Standard errors above the bound at which the net says "reflected light".
pub const SIGNIFICANCE: f64 = 3.0;

/// The net polarization of the mask's deepest tenth (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CorePolarization {
    /// `|Σ (s1, s2)| / Σ s0` over the deepest tenth.
    pub net: f64,
    /// The most that reflection by the surface gives there.
    pub bound: f64,
    /// Standard error of `net` from the sensor noise.
    pub standard_error: f64,
    /// Pixels counted.
    pub pixels: usize,
}

impl CorePolarization {
    /// The deepest tenth of `input`'s mask, by `prior`'s distances from
    /// the outline, read at refractive index `eta`; `None` without a lit,
    /// unclipped mask pixel. Unlit and clipped pixels are left out.
    pub fn of(
        input: &Input,
        prior: &ConvexityPrior,
        noise: &StokesNoise,
        eta: f64,
    ) -> Option<CorePolarization> {
        let counted =
            |i: usize| input.mask.data()[i] && !input.unlit.data()[i] && !input.saturated.data()[i];
        let distance = prior.distance.data();
        let mut depths: Vec<f32> = (0..input.mask.len())
            .filter(|&i| counted(i))
            .map(|i| distance[i])
            .collect();
        if depths.is_empty() {
            return None;
        }
        let at = ((1.0 - DEEPEST_SHARE) * (depths.len() - 1) as f64).round() as usize;
        let cut = *depths.select_nth_unstable_by(at, f32::total_cmp).1;
        let (mut sums, mut variance, mut pixels) = ([0.0f64; 3], 0.0, 0);
        for i in (0..input.mask.len()).filter(|&i| counted(i) && distance[i] >= cut) {
            let s0 = 2.0 * f64::from(input.intensity.data()[i]);
            let rho = f64::from(input.dop.data()[i]);
            let psi = 2.0 * f64::from(input.aop.data()[i]);
            sums[0] += s0;
            sums[1] += s0 * rho * psi.cos();
            sums[2] += s0 * rho * psi.sin();
            variance += noise.variance(s0);
            pixels += 1;
        }
        (sums[0] > 0.0).then(|| CorePolarization {
            net: sums[1].hypot(sums[2]) / sums[0],
            bound: specular_dop(DEEPEST_SHARE.sqrt().asin(), eta),
            standard_error: variance.sqrt() / sums[0],
            pixels,
        })
    }

    /// Whether the deepest tenth is polarized beyond what reflection by the
    /// surface gives there, by more than the noise explains.
    pub fn is_reflected_light(&self) -> bool {
        self.net - SIGNIFICANCE * self.standard_error > self.bound
    }

    /// What `sfp import` says of such a core, and what to do.
    pub fn warning(&self) -> String {
        format!(
            "the deepest tenth of the mask is polarized in one direction (net DoP {:.3} over {} \
             pixels, where reflection by the surface gives at most {:.3}): a compact light \
             reflected by rough facets, or a polarized light; SMSfP's default models it \
             (run.json: model.reflected_light), every other method reads it as the surface's",
            self.net, self.pixels, self.bound
        )
    }
}

/// Whether the mixed-model fit also models a compact light reflected by
/// rough microfacets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReflectedLight {
    Off,
    On,
    /// When the deepest tenth of the mask is polarized beyond what
    /// reflection by the surface gives there ([`CorePolarization`]).
    #[default]
    Auto,
}

impl Switch for ReflectedLight {
    const OFF: Self = ReflectedLight::Off;
    const ON: Self = ReflectedLight::On;
}

/// Why `"auto"` models the reflected light (`run.json`: `model`).
pub const REFLECTED_LIGHT_SEEN: &str = "the deepest tenth of the mask is polarized in one \
    direction beyond what reflection by the surface gives there: a compact light reflected by \
    rough facets, or a polarized light";

impl ReflectedLight {
    /// Whether the fit models the reflected light, and why, given the
    /// deepest tenth's polarization (`None`: no lit mask pixel).
    pub fn decide(self, core: Option<&CorePolarization>) -> (bool, &'static str) {
        match self {
            ReflectedLight::On => (true, "reflected_light = on"),
            ReflectedLight::Off => (false, "reflected_light = off"),
            ReflectedLight::Auto if core.is_some_and(CorePolarization::is_reflected_light) => {
                (true, REFLECTED_LIGHT_SEEN)
            }
            ReflectedLight::Auto => (
                false,
                "the deepest tenth of the mask is polarized no more than reflection by the \
                 surface gives there",
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::stokes_noise;
    use crate::prior::{DEFAULT_EXPONENT, convexity_prior};
    use crate::test_support::{analytic, glossy_sphere, with_reflected_light};
    use sfp_core::analytic::Shape;

    fn core(input: &Input) -> CorePolarization {
        let prior = convexity_prior(&input.mask, DEFAULT_EXPONENT);
        CorePolarization::of(input, &prior, &stokes_noise(input), 1.5).unwrap()
    }

    #[test]
    fn the_bound_is_the_specular_dop_at_the_edge_of_a_spheres_deepest_tenth() {
        let (input, _) = analytic(Shape::Sphere, 64, 1.5);
        let found = core(&input);
        assert!((found.bound - specular_dop(18.435f64.to_radians(), 1.5)).abs() < 1e-4);
        assert!((found.bound - 0.143).abs() < 1e-3, "{found:?}");
        // About a tenth of the lit mask pixels.
        let lit = (0..input.mask.len())
            .filter(|&i| input.mask.data()[i] && !input.unlit.data()[i])
            .count();
        let share = found.pixels as f64 / lit as f64;
        assert!((0.08..0.13).contains(&share), "{share}");
    }

    #[test]
    fn surface_reflection_cancels_and_a_reflected_light_does_not() {
        // Diffuse, and glossy (AoPs turned by the reflected surroundings):
        // the azimuths around the sphere's centre cancel.
        let (diffuse, _) = analytic(Shape::Sphere, 64, 1.5);
        let (glossy, _) = glossy_sphere(64, 3.0);
        for input in [&diffuse, &glossy] {
            let found = core(input);
            assert!(found.net < 0.3 * found.bound, "{found:?}");
            assert!(!found.is_reflected_light());
            assert!(!ReflectedLight::Auto.decide(Some(&found)).0);
        }
        // One direction of polarization, weaker than the bound: not enough.
        let weak = core(&with_reflected_light(
            diffuse.clone(),
            0.1,
            15f64.to_radians(),
            |_, _| true,
        ));
        assert!(weak.net > 0.08 && !weak.is_reflected_light(), "{weak:?}");
        // Stronger than any reflection at those zeniths: a reflected light.
        let strong = core(&with_reflected_light(
            diffuse,
            0.25,
            15f64.to_radians(),
            |_, _| true,
        ));
        assert!(strong.is_reflected_light(), "{strong:?}");
        let (on, why) = ReflectedLight::Auto.decide(Some(&strong));
        assert!(on && why == REFLECTED_LIGHT_SEEN);
        assert!(!ReflectedLight::Off.decide(Some(&strong)).0);
        assert!(ReflectedLight::On.decide(None).0);
        assert!(!ReflectedLight::Auto.decide(None).0);
    }
}
