//! Fresnel coefficients of a smooth dielectric and the diffuse and specular
//! degree-of-polarization models built on them (conventions.md §3).
//!
//! `eta` is the refractive index of the object relative to the outside medium
//! (air). Angles are in radians.

/// Largest refractive index of a material the renderer and the analytic
/// views accept: dielectrics up to germanium in the infrared (≈ 4). Above
/// it the model is not meant to be used, and at absurd values (1e155) `η²`
/// overflows into NaN Fresnel factors.
pub const MATERIAL_ETA_MAX: f64 = 4.0;

/// Checks a refractive index: finite, in `(1, max]`; the message shows
/// absurd values in scientific notation (1e155 reads better than its 156
/// digits).
pub fn check_eta(eta: f64, max: f64) -> crate::Result<()> {
    if eta > 1.0 && eta <= max {
        return Ok(());
    }
    let shown = if eta.abs() < 1e6 {
        format!("{eta}")
    } else {
        format!("{eta:e}")
    };
    Err(crate::Error::invalid(format!(
        "refractive index eta = {shown} must be in (1, {max}]"
    )))
}

/// Power reflectances `(R_s, R_p)` for light arriving from the outside at
/// incidence cosine `cos_i` on a dielectric of index `eta`.
///
/// Works for `eta < 1` too (light leaving a denser medium); beyond the critical
/// angle both reflectances are 1 (total internal reflection).
pub fn reflectance(cos_i: f64, eta: f64) -> (f64, f64) {
    if eta == 1.0 {
        return (0.0, 0.0); // no interface, even at grazing incidence
    }
    let cos_i = cos_i.abs().min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (rs * rs, rp * rp)
}

/// Power transmittances `(T_s, T_p) = (1 − R_s, 1 − R_p)`; by reciprocity the
/// same for light entering at `cos_i` and light leaving towards `cos_i`.
pub fn transmittance(cos_i: f64, eta: f64) -> (f64, f64) {
    let (rs, rp) = reflectance(cos_i, eta);
    (1.0 - rs, 1.0 - rp)
}

/// Transmittance of unpolarized light, `(T_s + T_p) / 2`: the factor the
/// diffuse model (conventions.md §3) puts on intensity at entry and exit.
pub fn unpolarized_transmittance(cos_i: f64, eta: f64) -> f64 {
    let (ts, tp) = transmittance(cos_i, eta);
    0.5 * (ts + tp)
}

/// Diffuse degree of polarization `ρ_d(θ, η)` (paper Eq. 6) of light that leaves
/// the surface at zenith angle `theta` after subsurface depolarization.
///
/// It equals `(T_p − T_s) / (T_p + T_s)` at exit angle `theta` (tested below).
pub fn diffuse_dop(theta: f64, eta: f64) -> f64 {
    let s2 = theta.sin().powi(2);
    let c = theta.cos();
    let a = eta - 1.0 / eta;
    let b = eta + 1.0 / eta;
    a * a * s2 / (2.0 + 2.0 * eta * eta - b * b * s2 + 4.0 * c * (eta * eta - s2).sqrt())
}

/// The largest diffuse DoP the model allows (grazing exit, `θ = 90°`).
/// About 0.384 at `η = 1.5`.
pub fn diffuse_dop_max(eta: f64) -> f64 {
    let a = eta - 1.0 / eta;
    let b = eta + 1.0 / eta;
    a * a / (2.0 + 2.0 * eta * eta - b * b)
}

/// Zenith angle from the diffuse DoP: the closed-form inverse of
/// [`diffuse_dop`] (paper Eq. 7, with the denominator erratum of
/// conventions.md §3 fixed).
///
/// `rho` is clamped to `[0, diffuse_dop_max(eta)]` first: noise pushes
/// measured DoP beyond the model, where the closed form returns nonsense.
/// Both `sin²θ` and `cos²θ` are evaluated from cancellation-free expressions
/// (`sin²θ = 1 − cos²θ` expanded symbolically), and `θ = atan2(sinθ, cosθ)`,
/// so the inverse is accurate to rounding near `θ = 0` as well as at grazing.
pub fn diffuse_zenith(rho: f64, eta: f64) -> f64 {
    let (sin, cos) = zenith_parts(rho, eta);
    sin.atan2(cos)
}

/// `(sin θ, cos θ)` of [`diffuse_zenith`]'s `θ`, without the angle: a
/// caller that needs only them (a normal, a shading term) skips an `atan2`
/// and a `sin_cos` per pixel.
pub fn diffuse_zenith_sin_cos(rho: f64, eta: f64) -> (f64, f64) {
    let (sin, cos) = zenith_parts(rho, eta);
    // Both parts are O(η⁴): no overflow for `hypot` (several times slower)
    // to guard against.
    let norm = (sin * sin + cos * cos).sqrt();
    if norm > 0.0 {
        (sin / norm, cos / norm)
    } else {
        (0.0, 1.0)
    }
}

/// `sin θ` and `cos θ` of [`diffuse_zenith`] up to one common positive
/// factor.
fn zenith_parts(rho: f64, eta: f64) -> (f64, f64) {
    let rho = if rho.is_nan() {
        0.0
    } else {
        rho.clamp(0.0, diffuse_dop_max(eta))
    };
    let (e2, e3, e4) = (eta * eta, eta.powi(3), eta.powi(4));
    let root = (1.0 - rho * rho).sqrt();
    let num = e4 * (1.0 - rho * rho) + 2.0 * e2 * (2.0 * rho * rho + rho - 1.0) + rho * rho
        - 4.0 * e3 * rho * root
        + 2.0 * rho
        + 1.0;
    // denominator − numerator, expanded: 2ρ[(ρ+1)(η⁴+η²) + 2η³√(1−ρ²)].
    let num_sin = 2.0 * rho * ((rho + 1.0) * (e4 + e2) + 2.0 * e3 * root);
    (num_sin.max(0.0).sqrt(), num.max(0.0).sqrt())
}

/// Specular degree of polarization `ρ_s(θ, η) = (R_s − R_p)/(R_s + R_p)` at
/// reflection angle `theta`; its AoP is perpendicular to the normal's azimuth.
pub fn specular_dop(theta: f64, eta: f64) -> f64 {
    let (rs, rp) = reflectance(theta.cos(), eta);
    if rs + rp <= 0.0 {
        return 0.0;
    }
    (rs - rp) / (rs + rp)
}

/// The zenith below Brewster's angle `atan η` whose specular DoP is `rho`
/// (bisection: `ρ_s` rises monotonically from 0 to 1 there).
pub fn specular_zenith_below_brewster(rho: f64, eta: f64) -> f64 {
    bisect(0.0, eta.atan(), |theta| specular_dop(theta, eta) < rho)
}

/// The zenith above Brewster's angle whose specular DoP is `rho` (`ρ_s`
/// falls monotonically from 1 to 0 between `atan η` and 90°): the other
/// branch of the specular inverse.
pub fn specular_zenith_above_brewster(rho: f64, eta: f64) -> f64 {
    bisect(eta.atan(), std::f64::consts::FRAC_PI_2, |theta| {
        specular_dop(theta, eta) > rho
    })
}

/// The point of `[lo, hi]` where `below` turns false, to 50 halvings.
fn bisect(mut lo: f64, mut hi: f64, below: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn both_specular_branches_invert_the_specular_dop() {
        let brewster = 1.5f64.atan().to_degrees();
        for deg in [5.0f64, 20.0, 40.0, 55.0, 60.0, 75.0, 88.0] {
            let theta = deg.to_radians();
            let rho = specular_dop(theta, 1.5);
            let back = if deg < brewster {
                specular_zenith_below_brewster(rho, 1.5)
            } else {
                specular_zenith_above_brewster(rho, 1.5)
            };
            assert!((back - theta).abs() < 1e-9, "{deg}: {}", back.to_degrees());
        }
    }

    #[test]
    fn normal_incidence_reflectance_is_textbook() {
        let (rs, rp) = reflectance(1.0, 1.5);
        assert!((rs - 0.04).abs() < 1e-12 && (rp - 0.04).abs() < 1e-12);
    }

    #[test]
    fn brewster_angle_has_no_p_reflection() {
        let eta: f64 = 1.5;
        let (rs, rp) = reflectance(eta.atan().cos(), eta);
        assert!(rp < 1e-20, "rp = {rp}");
        assert!(rs > 0.1);
        assert!((specular_dop(eta.atan(), eta) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn matched_index_reflects_nothing_even_at_grazing() {
        assert_eq!(reflectance(0.0, 1.0), (0.0, 0.0));
        assert_eq!(reflectance(0.5, 1.0), (0.0, 0.0));
    }

    #[test]
    fn total_internal_reflection_from_inside() {
        // Leaving glass (relative index 1/1.5) beyond the critical angle.
        let (rs, rp) = reflectance((60f64).to_radians().cos(), 1.0 / 1.5);
        assert_eq!((rs, rp), (1.0, 1.0));
    }

    #[test]
    fn diffuse_dop_is_fresnel_transmission_ratio() {
        for eta in [1.2, 1.5, 1.9] {
            for deg in [0.0, 10.0, 35.0, 60.0, 80.0, 89.5] {
                let theta = f64::to_radians(deg);
                let (ts, tp) = transmittance(theta.cos(), eta);
                let expected = (tp - ts) / (tp + ts);
                let got = diffuse_dop(theta, eta);
                assert!(
                    (got - expected).abs() < 1e-12,
                    "η={eta} θ={deg}: {got} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn diffuse_dop_max_is_value_at_grazing() {
        assert!((diffuse_dop_max(1.5) - diffuse_dop(FRAC_PI_2, 1.5)).abs() < 1e-12);
        assert!((diffuse_dop_max(1.5) - 0.384).abs() < 1e-3);
    }

    #[test]
    fn zenith_round_trip_property() {
        // θ ∈ [0, 89°] × η ∈ [1.1, 2.0] on a dense grid plus pseudo-random points.
        let mut worst: f64 = 0.0;
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut cases: Vec<(f64, f64)> = Vec::new();
        for i in 0..=890 {
            for j in 0..=9 {
                cases.push((f64::from(i) * 0.1, 1.1 + 0.1 * f64::from(j)));
            }
        }
        for _ in 0..20000 {
            cases.push((89.0 * next(), 1.1 + 0.9 * next()));
        }
        for (deg, eta) in cases {
            let theta = deg.to_radians();
            let rho = diffuse_dop(theta, eta);
            let back = diffuse_zenith(rho, eta);
            let (sin, cos) = diffuse_zenith_sin_cos(rho, eta);
            worst = worst
                .max((back - theta).abs())
                .max((sin - theta.sin()).abs())
                .max((cos - theta.cos()).abs());
        }
        assert!(worst < 1e-9, "worst round-trip error {worst:e}");
    }

    #[test]
    fn zenith_clamps_out_of_model_dop() {
        assert!((diffuse_zenith(0.9, 1.5) - FRAC_PI_2).abs() < 1e-6);
        assert_eq!(diffuse_zenith(-0.1, 1.5), 0.0);
        assert_eq!(diffuse_zenith(f64::NAN, 1.5), 0.0);
        assert_eq!(diffuse_zenith_sin_cos(-0.1, 1.5), (0.0, 1.0));
        assert_eq!(diffuse_zenith_sin_cos(f64::NAN, 1.5), (0.0, 1.0));
        let (sin, cos) = diffuse_zenith_sin_cos(0.9, 1.5);
        assert!((sin - 1.0).abs() < 1e-6 && cos.abs() < 2e-3, "{sin} {cos}");
    }
}
