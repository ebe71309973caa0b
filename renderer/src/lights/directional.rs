//! A distant light: `direction` towards it, `irradiance` on a surface facing
//! it, and an optional angular radius that makes it a uniform disk of
//! directions (the sun is 0.27°).
//!
//! `[[light]] type = "directional"`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `direction` | required | `[x, y, z]` towards the light (finite, non-zero) |
//! | `irradiance` | required | on a surface facing the light (≥ 0) |
//! | `angular_radius` | 0 | degrees, in [0, 90); > 0 makes a uniform disk of directions (soft shadows) |

use super::sample::LightSample;
use crate::scene_file::Table;
use glam::{DVec3, Vec3A};
use serde::{Deserialize, Serialize};
use sfp_core::Result;
use std::f32::consts::PI;

/// The scene file's `directional` light. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalDesc {
    pub direction: [f64; 3],
    pub irradiance: f64,
    #[serde(default)]
    pub angular_radius: f64,
}

impl DirectionalDesc {
    /// Checks the values serde cannot.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        let d = self.direction;
        if !d.iter().all(|x| x.is_finite()) || d.iter().all(|&x| x == 0.0) {
            return Err(t.err("direction", "must be a finite non-zero vector"));
        }
        if !(self.irradiance >= 0.0 && self.irradiance.is_finite()) {
            return Err(t.err("irradiance", "must be finite and ≥ 0"));
        }
        if !(0.0..90.0).contains(&self.angular_radius) {
            return Err(t.err("angular_radius", "must be in [0, 90) degrees"));
        }
        Ok(())
    }

    pub(crate) fn build(&self) -> Directional {
        Directional::new(
            DVec3::from(self.direction).as_vec3a(),
            self.irradiance as f32,
            (self.angular_radius as f32).to_radians(),
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Directional {
    /// Unit vector towards the light.
    pub direction: Vec3A,
    pub irradiance: f32,
    /// `cos` of the angular radius (1 for a delta light).
    pub cos_max: f32,
}

impl Directional {
    pub fn new(direction: Vec3A, irradiance: f32, angular_radius: f32) -> Self {
        Directional {
            direction: direction.normalize(),
            irradiance,
            cos_max: angular_radius.cos(),
        }
    }

    /// Delta light: the exact direction. Disk: uniform over the cone, with
    /// radiance `E / (π sin²r)` so a facing surface receives `E`
    /// (`∫ L cosθ dω = L π sin²r` over the cone).
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> LightSample {
        if self.cos_max >= 1.0 {
            return LightSample {
                wi: self.direction,
                value: self.irradiance,
                dist: f32::INFINITY,
                pdf: 0.0,
            };
        }
        let cos = 1.0 - u[0] * (1.0 - self.cos_max);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u[1];
        let (t, b) = self.direction.any_orthonormal_pair();
        let wi = (t * (sin * phi.cos()) + b * (sin * phi.sin()) + self.direction * cos).normalize();
        let solid_angle = 2.0 * PI * (1.0 - self.cos_max);
        let sin2_max = 1.0 - self.cos_max * self.cos_max;
        let radiance = self.irradiance / (PI * sin2_max);
        LightSample {
            wi,
            value: radiance * solid_angle,
            dist: f32::INFINITY,
            // Not reachable by BSDF sampling (handled as a delta light in MIS).
            pdf: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, Stream};

    #[test]
    fn disk_light_gives_stated_irradiance_on_facing_surface() {
        let l = Directional::new(Vec3A::new(0.0, 0.3, 1.0), 2.0, 10f32.to_radians());
        let mut s = Sampler::new(3, Stream::Path, 0, 0, 0);
        let n = 100_000;
        let e: f64 = (0..n)
            .map(|_| {
                let ls = l.sample(s.next_2d());
                f64::from(ls.value * ls.wi.dot(l.direction))
            })
            .sum::<f64>()
            / f64::from(n);
        assert!((e - 2.0).abs() < 2e-3, "{e}");
    }
}
