//! Rough dielectric reflection: a GGX microfacet lobe whose microfacets reflect
//! with the full Fresnel reflection Mueller matrix (Mitsuba's `pplastic`
//! specular part). Its AoP is perpendicular to the plane of reflection, the
//! "specular contamination" that breaks the diffuse model.
//!
//! `f = D(h) G(ω_o, ω_i) / (4 cosθ_i cosθ_o) · R(h)`; `roughness` is the GGX `α`.

use super::fresnel::amplitudes;
use crate::mueller::{Mueller, s_axis};
use glam::Vec3A;
use std::f32::consts::PI;

/// Smallest `α` used: a perfect mirror cannot be hit by next-event estimation.
pub const MIN_ALPHA: f32 = 1e-3;

/// GGX normal distribution `D(h)` for `cos_h = n·h`.
#[inline]
pub fn ggx_d(cos_h: f32, alpha: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let k = cos_h * cos_h * (a2 - 1.0) + 1.0;
    a2 / (PI * k * k)
}

/// Smith masking `G1` for a direction at cosine `cos` to the normal.
#[inline]
fn smith_g1(cos: f32, alpha: f32) -> f32 {
    let c2 = (cos * cos).max(1e-12);
    let tan2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// Fresnel reflection Mueller matrix at a facet, in its own s/p frames.
#[inline]
pub fn reflection(cos_i: f32, eta: f32) -> Mueller {
    let (rs, rp) = amplitudes(cos_i, eta);
    Mueller::fresnel(rs * rs, rp * rp, rs * rp)
}

/// `f · cosθ_i` in the exit frame `s_axis(ω_o, n)` and incidence frame
/// `s_axis(−ω_i, n)` used by every lobe. Zero when `ω_o` and `ω_i` are not on
/// the outer side.
pub fn eval(n: Vec3A, wo: Vec3A, wi: Vec3A, eta: f32, alpha: f32) -> Mueller {
    let (cos_o, cos_i) = (n.dot(wo), n.dot(wi));
    if cos_o <= 0.0 || cos_i <= 0.0 {
        return Mueller::ZERO;
    }
    let h = (wo + wi).normalize();
    let cos_d = wi.dot(h).clamp(0.0, 1.0);
    let scale =
        ggx_d(n.dot(h), alpha) * smith_g1(cos_o, alpha) * smith_g1(cos_i, alpha) / (4.0 * cos_o);
    // Facet matrix, then rotations from the facet s/p frames to the macro ones.
    let facet = reflection(cos_d, eta).scale(scale);
    let out_rot = Mueller::rotation(wo, s_axis(wo, h), s_axis(wo, n));
    (out_rot * facet).then_rotated_input(-wi, s_axis(-wi, n), s_axis(-wi, h))
}

/// Samples `h ∝ D(h) cosθ_h` and reflects `ω_o` about it.
pub fn sample(n: Vec3A, wo: Vec3A, alpha: f32, u: [f32; 2]) -> Option<Vec3A> {
    let (t, b) = n.any_orthonormal_pair();
    let phi = 2.0 * PI * u[0];
    let tan2 = alpha * alpha * u[1] / (1.0 - u[1]).max(1e-12);
    let cos_h = (1.0 + tan2).sqrt().recip();
    let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
    let h = (t * phi.cos() + b * phi.sin()) * sin_h + n * cos_h;
    let wi = 2.0 * wo.dot(h) * h - wo;
    (wi.dot(n) > 0.0).then_some(wi)
}

/// Solid-angle density of [`sample`].
pub fn pdf(n: Vec3A, wo: Vec3A, wi: Vec3A, alpha: f32) -> f32 {
    if n.dot(wi) <= 0.0 || n.dot(wo) <= 0.0 {
        return 0.0;
    }
    let h = (wo + wi).normalize();
    let cos_h = n.dot(h);
    ggx_d(cos_h, alpha) * cos_h / (4.0 * wo.dot(h).abs().max(1e-12))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::fresnel::{reflectance, specular_dop};

    #[test]
    fn facet_matrix_matches_power_reflectances() {
        for deg in [0.0f32, 20.0, 56.3, 80.0] {
            let c = deg.to_radians().cos();
            let m = reflection(c, 1.5);
            let (rs, rp) = reflectance(f64::from(c), 1.5);
            assert!((f64::from(m.0[0][0]) - 0.5 * (rs + rp)).abs() < 1e-6);
            let dop = f64::from(m.0[1][0] / m.0[0][0]);
            let expect = specular_dop(f64::from(deg).to_radians(), 1.5);
            assert!((dop - expect).abs() < 1e-5, "{deg}: {dop} vs {expect}");
        }
    }

    #[test]
    fn ggx_is_normalised_over_projected_area() {
        // ∫ D(h) cosθ_h dω_h = 1, by midpoint quadrature in θ.
        for alpha in [0.1f32, 0.3, 0.8] {
            let n = 20000;
            let integral: f64 = (0..n)
                .map(|k| {
                    let th = (k as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                    let d = f64::from(ggx_d(th.cos() as f32, alpha));
                    d * th.cos()
                        * th.sin()
                        * 2.0
                        * std::f64::consts::PI
                        * (std::f64::consts::FRAC_PI_2 / n as f64)
                })
                .sum();
            assert!((integral - 1.0).abs() < 2e-3, "α={alpha}: {integral}");
        }
    }

    #[test]
    fn mirror_direction_is_polarized_perpendicular_to_plane() {
        // Near-mirror lobe, ω_o in the x–z plane: reflected unpolarized light
        // is s-polarized, i.e. along y, s1 < 0 in a frame with x in the plane.
        let n = Vec3A::Z;
        let wo = Vec3A::new(0.6, 0.0, 0.8);
        let wi = Vec3A::new(-0.6, 0.0, 0.8);
        let m = eval(n, wo, wi, 1.5, 0.05);
        let s = m.apply([1.0, 0.0, 0.0, 0.0]);
        // The exit frame's x axis is s_axis(wo, n) ∥ y, so s-polarized is s1 > 0.
        assert!(s[0] > 0.0 && s[1] > 0.0 && s[2].abs() < 1e-4 * s[0]);
        let expect = specular_dop(0.6f64.asin(), 1.5) as f32;
        assert!((s[1] / s[0] - expect).abs() < 1e-4);
    }
}
