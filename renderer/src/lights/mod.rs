//! Light sources. Emission is unpolarized, so a light contributes a scalar
//! radiance; polarization arises only at surfaces. The environment is kept
//! apart from the [`Light`] list: rays that escape the scene reach it.

pub mod area;
pub mod directional;
pub mod environment;
pub mod point;

pub use area::Area;
pub use directional::Directional;
pub use environment::Environment;
pub use point::Point;

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

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    Directional(Directional),
    Point(Point),
    Area(Area),
}

impl Light {
    /// The one direction every shadow ray towards this light takes, from
    /// any point: a delta distant light's.
    pub fn parallel_direction(&self) -> Option<Vec3A> {
        match self {
            Light::Directional(l) if l.cos_max >= 1.0 => Some(l.direction),
            _ => None,
        }
    }

    #[inline]
    pub fn sample(&self, p: Vec3A, u: [f32; 2]) -> LightSample {
        match self {
            Light::Directional(l) => l.sample(u),
            Light::Point(l) => l.sample(p),
            Light::Area(l) => l.sample(p, u),
        }
    }
}
