//! Constant unpolarized environment radiance: the furnace test's light.
//! Sampled uniformly over the sphere and combined with BSDF sampling by MIS.

use super::LightSample;
use glam::Vec3A;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    pub radiance: f32,
}

/// Density of uniform sphere sampling.
pub const PDF: f32 = 1.0 / (4.0 * PI);

impl Environment {
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> LightSample {
        let z = 1.0 - 2.0 * u[0];
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u[1];
        LightSample {
            wi: Vec3A::new(r * phi.cos(), r * phi.sin(), z),
            value: self.radiance / PDF,
            dist: f32::INFINITY,
            pdf: PDF,
        }
    }
}
