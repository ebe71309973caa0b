//! An isotropic point light of radiant intensity `intensity` (per steradian).

use super::LightSample;
use glam::Vec3A;

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
