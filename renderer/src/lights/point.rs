//! An isotropic point light of radiant intensity `intensity` (per steradian).
//!
//! `[[light]] type = "point"`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `position` | required | `[x, y, z]` (finite) |
//! | `intensity` | required | radiant intensity, per steradian (≥ 0); irradiance falls with the inverse square of the distance |

use super::sample::LightSample;
use crate::scene_file::Table;
use glam::{DVec3, Vec3A};
use serde::{Deserialize, Serialize};
use sfp_core::Result;

/// The scene file's `point` light. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointDesc {
    pub position: [f64; 3],
    pub intensity: f64,
}

impl PointDesc {
    /// Checks the values serde cannot.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        if !self.position.iter().all(|x| x.is_finite()) {
            return Err(t.err("position", "must be finite"));
        }
        if !(self.intensity >= 0.0 && self.intensity.is_finite()) {
            return Err(t.err("intensity", "must be finite and ≥ 0"));
        }
        Ok(())
    }

    pub(crate) fn build(&self) -> Point {
        Point {
            position: DVec3::from(self.position).as_vec3a(),
            intensity: self.intensity as f32,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub position: Vec3A,
    pub intensity: f32,
}

impl Point {
    /// Inverse-square irradiance on a surface facing the light.
    #[inline]
    pub fn sample(&self, p: Vec3A) -> LightSample {
        let d = self.position - p;
        let dist2 = d.length_squared().max(1e-12);
        let dist = dist2.sqrt();
        LightSample {
            wi: d / dist,
            value: self.intensity / dist2,
            dist,
            pdf: 0.0,
        }
    }
}
