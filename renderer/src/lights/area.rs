//! A square area light: one-sided, emitting constant unpolarized `radiance`
//! towards the side its `normal` points to. Sampled uniformly by area for
//! next-event estimation and hit by BSDF-sampled rays, combined by MIS.
//!
//! The light is not part of the scene geometry: it casts no shadow, and a
//! path that hits it ends there.
//!
//! `[[light]] type = "area"`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `center` | required | `[x, y, z]` (finite) |
//! | `normal` | required | the side it lights (finite, non-zero) |
//! | `size` | required | side length of the square (> 0) |
//! | `radiance` | required | emitted radiance (≥ 0) |

use super::sample::LightSample;
use crate::scene_file::Table;
use glam::{DVec3, Vec3A};
use serde::{Deserialize, Serialize};
use sfp_core::Result;

/// The scene file's `area` light. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaDesc {
    pub center: [f64; 3],
    pub normal: [f64; 3],
    pub size: f64,
    pub radiance: f64,
}

impl AreaDesc {
    /// Checks the values serde cannot.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if !finite(&self.center) || !finite(&self.normal) || self.normal.iter().all(|&x| x == 0.0) {
            return Err(t.err("normal", "center and a non-zero normal must be finite"));
        }
        if !(self.size > 0.0 && self.size.is_finite()) {
            return Err(t.err("size", "must be positive"));
        }
        if !(self.radiance >= 0.0 && self.radiance.is_finite()) {
            return Err(t.err("radiance", "must be finite and ≥ 0"));
        }
        Ok(())
    }

    pub(crate) fn build(&self) -> Area {
        let v3 = |a: [f64; 3]| DVec3::from(a).as_vec3a();
        Area::new(
            v3(self.center),
            v3(self.normal),
            self.size as f32,
            self.radiance as f32,
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Area {
    pub center: Vec3A,
    /// Unit emitting direction.
    pub normal: Vec3A,
    /// Half-edge vectors spanning the square.
    pub half_u: Vec3A,
    pub half_v: Vec3A,
    pub radiance: f32,
}

impl Area {
    pub fn new(center: Vec3A, normal: Vec3A, size: f32, radiance: f32) -> Area {
        let normal = normal.normalize();
        let u = normal.any_orthonormal_vector();
        Area {
            center,
            normal,
            half_u: u * (0.5 * size),
            half_v: normal.cross(u) * (0.5 * size),
            radiance,
        }
    }

    fn area(&self) -> f32 {
        4.0 * self.half_u.length() * self.half_v.length()
    }

    /// Solid-angle density of a uniform area sample seen from distance
    /// `dist` along `wi`: `dist² / (cosθ_l · A)`.
    #[inline]
    fn solid_angle_pdf(&self, wi: Vec3A, dist: f32) -> f32 {
        let cos_l = -wi.dot(self.normal);
        if cos_l <= 0.0 {
            return 0.0;
        }
        dist * dist / (cos_l * self.area())
    }

    #[inline]
    pub fn sample(&self, p: Vec3A, u: [f32; 2]) -> LightSample {
        let q = self.center + self.half_u * (2.0 * u[0] - 1.0) + self.half_v * (2.0 * u[1] - 1.0);
        let d = q - p;
        let dist = d.length();
        let wi = d / dist;
        let pdf = self.solid_angle_pdf(wi, dist);
        LightSample {
            wi,
            value: if pdf > 0.0 { self.radiance / pdf } else { 0.0 },
            dist,
            pdf,
        }
    }

    /// Distance to the emitting face along unit `dir`, if hit within `tmax`,
    /// and the solid-angle density light sampling would have had there.
    #[inline]
    pub fn hit(&self, origin: Vec3A, dir: Vec3A, tmax: f32) -> Option<(f32, f32)> {
        let denom = self.normal.dot(dir);
        if denom >= 0.0 {
            return None; // parallel, or arriving at the back side
        }
        let t = self.normal.dot(self.center - origin) / denom;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        let q = origin + dir * t - self.center;
        let inside = |h: Vec3A| q.dot(h).abs() <= h.length_squared();
        (inside(self.half_u) && inside(self.half_v)).then(|| (t, self.solid_angle_pdf(dir, t)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, Stream};

    /// Irradiance under the centre of a facing square: light sampling against
    /// a midpoint quadrature of `∫ L cosθ cosθ_l / r² dA`.
    #[test]
    fn sampled_irradiance_matches_quadrature() {
        let light = Area::new(Vec3A::new(0.0, 0.0, 1.0), -Vec3A::Z, 1.5, 2.0);
        let p = Vec3A::ZERO;
        let mut s = Sampler::new(5, Stream::Path, 0, 0, 0);
        let n = 200_000;
        let mc: f64 = (0..n)
            .map(|_| {
                let ls = light.sample(p, s.next_2d());
                f64::from(ls.value * ls.wi.z.max(0.0))
            })
            .sum::<f64>()
            / f64::from(n);
        // E = ∫∫ L cosθ cosθ_l / r² dA over the square (midpoint rule).
        let m = 400;
        let h = 1.5 / m as f64;
        let mut quad = 0.0;
        for i in 0..m {
            for j in 0..m {
                let x = -0.75 + (i as f64 + 0.5) * h;
                let y = -0.75 + (j as f64 + 0.5) * h;
                let r2: f64 = x * x + y * y + 1.0;
                quad += 2.0 * (1.0 / r2.sqrt()).powi(2) / r2 * h * h;
            }
        }
        assert!((mc / quad - 1.0).abs() < 5e-3, "{mc} vs {quad}");
        let (t, pdf) = light.hit(p, Vec3A::Z, f32::INFINITY).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (pdf - 1.0 / 2.25).abs() < 1e-6);
        assert!(light.hit(p, -Vec3A::Z, f32::INFINITY).is_none());
        assert!(
            light
                .hit(Vec3A::new(0.0, 0.0, 2.0), -Vec3A::Z, f32::INFINITY)
                .is_none()
        );
    }
}
