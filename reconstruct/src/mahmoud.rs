//! Mahmoud, El-Melegy & Farag, "Direct method for shape recovery from
//! polarization and shading", Proc. ICIP 2012, 1769–1772 — the
//! polarization-plus-shading baseline of the paper's Table 1.
//!
//! # Method (per pixel, no spatial coupling)
//! 1. Zenith from the DoP by the diffuse model's closed-form inverse
//!    (paper Eq. 7 with the erratum of conventions.md §3): `θ = θ_d(ρ, η)`.
//! 2. Polarization candidates `p± = (±sinθ cosψ, ±sinθ sinψ, cosθ)`.
//! 3. Lambertian shading `I_un = α n·l` (light vector `l` = direction ×
//!    irradiance) gives the plane `n·l = r`, `r = I_un/α`. With `n_z = cosθ`
//!    it meets the unit sphere where `sinθ (n̂_xy·l_xy) = r − cosθ l_z`. With
//!    `m = |l_xy|`, `u = l_xy/m`, `u⊥ = (−u_y, u_x)` and
//!    `k = (r − cosθ l_z)/(m sinθ)`, the two intersection points are
//!    `n_xy = sinθ (k u ± √(1−k²) u⊥)`, `n_z = cosθ` — valid for any light
//!    azimuth (no component of one point is borrowed from the other).
//! 4. Of the two points, take the one closer to either polarization
//!    candidate; combine it with the polarization candidate nearest to it by
//!    averaging the two azimuths (bisector of the two unit azimuth vectors),
//!    keeping `θ`.
//!
//! # Parameters (defaults)
//! - `eta = 1.5` (the reference implementations' value).
//! - light: known (`l`, `α`), or estimated from the polarization image by the
//!   shared light estimation, which folds `α` into `l`.
//!
//! # Choices the paper leaves open (fallbacks, counted in `run.json`)
//! - **No intersection** (`|k| > 1`: noise, a wrong `α`, `θ` or light): the
//!   shading-only estimate is the point of the zenith circle that best
//!   satisfies the shading equation — azimuth of `l_xy` when the pixel is too
//!   bright (`k > 1`), opposite when too dark (`k < −1`); the output is the
//!   polarization candidate nearest to it (not averaged).
//! - **Dark pixels** ([`Input::dark`]: attached or cast shadow, `I_un` says
//!   only `n·l ≲ 0`): the same fallback with the "too dark" estimate, i.e. the
//!   polarization candidate facing away from the light.
//! - **No azimuth information** (`m sinθ ≈ 0`: a light along the view axis,
//!   or `θ = 0`): shading cannot separate the candidates; azimuth `ψ ∈ [0, π)`
//!   is returned. With a frontal light the method therefore degenerates to
//!   undisambiguated polarization.

use crate::atkinson::zenith_azimuth_normal;
use crate::input::Input;
use crate::method::{Method, Reconstruction};
use sfp_core::{Error, Image, Mask, NormalMap, Result};

/// Below this `m sinθ / |l|` the shading plane carries no azimuth information.
const MIN_AZIMUTH_LEVER: f64 = 1e-9;

/// `|k|` up to `1 +` this counts as tangent rather than missing.
const TANGENT_TOLERANCE: f64 = 1e-12;

/// How a pixel's normal was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Intersection point averaged with its nearest polarization candidate.
    Combined,
    /// The shading plane misses the zenith circle: fallback.
    NoIntersection,
    /// Dark pixel: fallback to the candidate facing away from the light.
    Dark,
    /// Shading cannot tell the candidates apart: azimuth `ψ`.
    NoAzimuthInformation,
}

/// The (at most two) unit normals with zenith `theta` that satisfy
/// `n·light = r`; `None` when the plane misses the zenith circle or does not
/// depend on the azimuth (`|l_xy| sinθ ≈ 0`).
pub fn shading_zenith_intersection(theta: f64, light: [f64; 3], r: f64) -> Option<[[f64; 3]; 2]> {
    let (s, c) = (theta.sin(), theta.cos());
    let norm = (light[0] * light[0] + light[1] * light[1] + light[2] * light[2]).sqrt();
    let m = light[0].hypot(light[1]);
    if m * s <= MIN_AZIMUTH_LEVER * norm {
        return None;
    }
    let k = (r - c * light[2]) / (m * s);
    // A tangent plane (|k| = 1) must not be lost to rounding.
    if k.abs() > 1.0 + TANGENT_TOLERANCE {
        return None;
    }
    let k = k.clamp(-1.0, 1.0);
    let (ux, uy) = (light[0] / m, light[1] / m);
    let q = (1.0 - k * k).sqrt();
    let point = |sign: f64| {
        [
            s * (k * ux - sign * q * uy),
            s * (k * uy + sign * q * ux),
            c,
        ]
    };
    Some([point(1.0), point(-1.0)])
}

/// The Mahmoud et al. normal of one pixel with zenith `theta`, AoP `psi`,
/// shading target `r = I_un/α` (`None` for a dark pixel) and light `light`.
pub fn pixel_normal(theta: f64, psi: f64, r: Option<f64>, light: [f64; 3]) -> ([f64; 3], Outcome) {
    let p = zenith_azimuth_normal(theta, psi);
    let flipped = [-p[0], -p[1], p[2]];
    // Picks p or its flip by the sign of p_xy·d.
    let towards = |d: [f64; 2]| {
        if p[0] * d[0] + p[1] * d[1] >= 0.0 {
            p
        } else {
            flipped
        }
    };
    let (s, c) = (theta.sin(), theta.cos());
    let norm = (light[0] * light[0] + light[1] * light[1] + light[2] * light[2]).sqrt();
    let m = light[0].hypot(light[1]);
    if m * s <= MIN_AZIMUTH_LEVER * norm {
        return (p, Outcome::NoAzimuthInformation);
    }
    let away = [-light[0], -light[1]];
    let Some(r) = r else {
        return (towards(away), Outcome::Dark);
    };
    let Some(points) = shading_zenith_intersection(theta, light, r) else {
        let too_bright = r - c * light[2] > 0.0;
        let estimate = if too_bright {
            [light[0], light[1]]
        } else {
            away
        };
        return (towards(estimate), Outcome::NoIntersection);
    };
    // |n_xy·p_xy| is the closeness of n to the nearer of p and its flip.
    let closeness = |n: &[f64; 3]| (n[0] * p[0] + n[1] * p[1]).abs();
    let n = if closeness(&points[1]) > closeness(&points[0]) {
        points[1]
    } else {
        points[0]
    };
    let q = towards([n[0], n[1]]);
    // Bisector of the two azimuths (both xy parts have length sinθ and make
    // an angle of at most 90°, so the sum does not vanish).
    let (bx, by) = (n[0] + q[0], n[1] + q[1]);
    let len = bx.hypot(by);
    ([s * bx / len, s * by / len, c], Outcome::Combined)
}

/// Per-pixel outcome counts of a run.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct OutcomeCounts {
    pub combined: usize,
    pub no_intersection: usize,
    pub dark: usize,
    pub no_azimuth_information: usize,
}

/// Mahmoud et al. normals over `mask` from zenith `theta`, AoP `aop`,
/// intensity `I_un`, with `I_un = albedo · n·light`; `dark` pixels take the
/// shadow fallback.
pub fn normals(
    theta: &Image<f32>,
    aop: &Image<f32>,
    intensity: &Image<f32>,
    mask: &Mask,
    dark: &Mask,
    light: [f64; 3],
    albedo: f64,
) -> Result<(NormalMap, OutcomeCounts)> {
    let size = mask.size();
    if [theta.size(), aop.size(), intensity.size(), dark.size()]
        .iter()
        .any(|&s| s != size)
    {
        return Err(Error::invalid(
            "zenith, AoP, intensity and masks differ in size",
        ));
    }
    if !(albedo > 0.0 && albedo.is_finite()) || light.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid(format!(
            "Mahmoud needs a finite light and albedo > 0 (light {light:?}, albedo {albedo})"
        )));
    }
    let mut out = Image::new(size.0, size.1, [0.0f32; 3]);
    let mut counts = OutcomeCounts::default();
    for i in 0..mask.len() {
        if !mask.data()[i] {
            continue;
        }
        let r = (!dark.data()[i]).then(|| f64::from(intensity.data()[i]) / albedo);
        let (n, outcome) = pixel_normal(
            f64::from(theta.data()[i]),
            f64::from(aop.data()[i]),
            r,
            light,
        );
        out.data_mut()[i] = n.map(|v| v as f32);
        match outcome {
            Outcome::Combined => counts.combined += 1,
            Outcome::NoIntersection => counts.no_intersection += 1,
            Outcome::Dark => counts.dark += 1,
            Outcome::NoAzimuthInformation => counts.no_azimuth_information += 1,
        }
    }
    Ok((out, counts))
}

/// Where the Lambertian light comes from.
#[derive(Clone, Debug, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MahmoudLight {
    /// Known light vector (direction × irradiance, camera frame) and albedo:
    /// `I_un = albedo · n·light` in the input's intensity units.
    Known { light: [f64; 3], albedo: f64 },
}

/// Parameters of [`Mahmoud`]; see the module documentation.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MahmoudParams {
    pub eta: f64,
    pub light: MahmoudLight,
}

/// The Mahmoud et al. 2012 method behind the common [`Method`] interface.
#[derive(Clone, Debug)]
pub struct Mahmoud {
    pub params: MahmoudParams,
}

impl Method for Mahmoud {
    fn name(&self) -> &str {
        "mahmoud"
    }

    fn reconstruct(&self, input: &Input) -> Result<Reconstruction> {
        let start = std::time::Instant::now();
        let (theta, clamped) = input.zenith(self.params.eta);
        let MahmoudLight::Known { light, albedo } = self.params.light;
        let (normals, outcomes) = normals(
            &theta,
            &input.aop,
            &input.intensity,
            &input.mask,
            &input.dark,
            light,
            albedo,
        )?;
        let normals_seconds = start.elapsed().as_secs_f64();
        let start = std::time::Instant::now();
        let height = crate::integrate::height_from_normals(&normals, &input.mask)?;
        let run = serde_json::json!({
            "method": self.name(),
            "params": self.params,
            "light_used": light,
            "albedo_used": albedo,
            "dop_clamped_pixels": clamped,
            "outcomes": outcomes,
            "timings": {
                "normals_seconds": normals_seconds,
                "integration_seconds": start.elapsed().as_secs_f64(),
            },
        });
        Ok(Reconstruction {
            normals,
            height,
            run,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12)
    }

    /// Both points match hand-computed ones, in either order.
    fn check(theta: f64, light: [f64; 3], r: f64, expected: [[f64; 3]; 2]) {
        let [a, b] = shading_zenith_intersection(theta, light, r).expect("intersects");
        assert!(
            (close(a, expected[0]) && close(b, expected[1]))
                || (close(a, expected[1]) && close(b, expected[0])),
            "got {a:?} {b:?}, expected {expected:?}"
        );
        for n in [a, b] {
            assert!((dot(n, n) - 1.0).abs() < 1e-12);
            assert!((dot(n, light) - r).abs() < 1e-12);
            assert!((n[2] - theta.cos()).abs() < 1e-12);
        }
    }

    #[test]
    fn intersection_hand_computed_cases() {
        let h = 0.5f64.sqrt();
        // Light along +x, θ = 60°: n_x = r / l_x = 0.5, n_y = ±√(3/4 − 1/4).
        let t = PI / 3.0;
        let c = t.cos();
        check(t, [1.0, 0.0, 0.0], 0.5, [[0.5, h, c], [0.5, -h, c]]);
        // Light along −y with a z part, θ = 45°: n_z = √½, n·l = −n_y·1 + √½·1.
        // With r = √½: n_y = 0, n_x = ±√½.
        check(PI / 4.0, [0.0, -1.0, 1.0], h, [[h, 0.0, h], [-h, 0.0, h]]);
        // Light in the (1,1) diagonal, l = (0.6, 0.6, 0.5), θ = 90°:
        // 0.6 (n_x + n_y) = r = 0.6 → n_x + n_y = 1, n_x² + n_y² = 1 →
        // (1, 0, 0) and (0, 1, 0).
        check(
            PI / 2.0,
            [0.6, 0.6, 0.5],
            0.6,
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        );
        // Light with x and y parts, l = (−3, 4, 0)/5 · 2, θ = 90°, r = 0:
        // n ⟂ (−3, 4) → ±(4, 3)/5.
        check(
            PI / 2.0,
            [-1.2, 1.6, 0.0],
            0.0,
            [[0.8, 0.6, 0.0], [-0.8, -0.6, 0.0]],
        );
        // Tangent case, k = 1: one double point along the light's azimuth.
        let s = t.sin();
        check(t, [0.0, 1.0, 1.0], s + c, [[0.0, s, c], [0.0, s, c]]);
    }

    #[test]
    fn intersection_absent_cases() {
        // Too bright for this zenith, too dark, frontal light, θ = 0.
        assert!(shading_zenith_intersection(1.0, [1.0, 0.0, 0.0], 0.95).is_none());
        assert!(shading_zenith_intersection(1.0, [1.0, 0.0, 0.0], -0.95).is_none());
        assert!(shading_zenith_intersection(0.5, [0.0, 0.0, 1.0], 0.5f64.cos()).is_none());
        assert!(shading_zenith_intersection(0.0, [0.3, 0.4, 1.0], 1.0).is_none());
    }

    /// The true normal is recovered exactly for lights in every azimuth and
    /// normals in every azimuth (except on the tie where the mirror point
    /// equals the flipped candidate, `φ − φ_l = ±90°`).
    #[test]
    fn pixel_normal_recovers_truth_for_any_light_azimuth() {
        let mut worst: f64 = 0.0;
        for la in 0..12 {
            let phi_l = la as f64 * PI / 6.0 + 0.1;
            let light = [0.5 * phi_l.cos(), 0.5 * phi_l.sin(), 0.866];
            for na in 0..36 {
                let phi = na as f64 * PI / 18.0 + 0.05;
                let rel = (phi - phi_l).rem_euclid(PI);
                if (rel - PI / 2.0).abs() < 1e-3 {
                    continue;
                }
                for theta in [0.2, 0.7, 1.2] {
                    let n = zenith_azimuth_normal(theta, phi);
                    let r = dot(n, light);
                    if r <= 0.0 {
                        continue;
                    }
                    let psi = phi.rem_euclid(PI);
                    let (got, outcome) = pixel_normal(theta, psi, Some(r), light);
                    assert_eq!(outcome, Outcome::Combined);
                    worst = worst.max((dot(got, n).clamp(-1.0, 1.0)).acos());
                }
            }
        }
        assert!(worst < 1e-6, "worst error {worst} rad");
    }

    #[test]
    fn fallbacks_pick_the_sensible_candidate() {
        let light = [0.5, 0.0, 0.866];
        let theta = 1.0;
        // Dark: the candidate facing away from the light (n_x < 0).
        let (n, o) = pixel_normal(theta, 0.0, None, light);
        assert_eq!(o, Outcome::Dark);
        assert!(n[0] < 0.0);
        // Too bright: the candidate facing the light.
        let (n, o) = pixel_normal(theta, 0.0, Some(2.0), light);
        assert_eq!(o, Outcome::NoIntersection);
        assert!(n[0] > 0.0);
        // Frontal light: azimuth ψ.
        let (n, o) = pixel_normal(theta, 2.0, Some(0.5), [0.0, 0.0, 1.0]);
        assert_eq!(o, Outcome::NoAzimuthInformation);
        assert!((n[1].atan2(n[0]) - 2.0).abs() < 1e-12);
    }
}
