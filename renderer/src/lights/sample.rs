//! What sampling a light gives a shading point: the one currency of every
//! light kind.

use glam::Vec3A;

/// A light sample seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction towards the light.
    pub wi: Vec3A,
    /// Incident radiance divided by the sampling density (for delta lights:
    /// the irradiance on a surface facing the light).
    pub value: f32,
    /// Distance to the light (`INFINITY` for distant lights).
    pub dist: f32,
    /// Solid-angle density, for multiple importance sampling; 0 for delta
    /// lights, which BSDF sampling cannot hit.
    pub pdf: f32,
}
