//! Light sources. Emission is unpolarized, so a light contributes a scalar
//! radiance; polarization arises only at surfaces. The environment is kept
//! apart from the [`Light`] list: rays that escape the scene reach it.
//!
//! One file per kind of `[[light]]` (`type = "..."`), each holding its
//! description (the TOML keys, with their table in the file's doc comment),
//! its validation, its build and its sampling. This module lists the kinds
//! and dispatches to them; a new kind is a file and a line in
//! [`LightDesc`] and in each `match` here.

pub mod area;
pub mod directional;
pub mod environment;
pub mod point;
pub mod sample;
pub mod surroundings;

pub use area::{Area, AreaDesc};
pub use directional::{Directional, DirectionalDesc};
pub use environment::{Environment, EnvironmentDesc};
pub use point::{Point, PointDesc};
pub use sample::LightSample;

use crate::scene_file::Table;
use glam::Vec3A;
use serde::{Deserialize, Serialize};
use sfp_core::Result;

/// A `[[light]]` table of a scene file: its `type` names the kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum LightDesc {
    Directional(DirectionalDesc),
    Point(PointDesc),
    Environment(EnvironmentDesc),
    Area(AreaDesc),
}

/// What a light description builds: a light the path tracer samples, or
/// the environment that escaping rays reach.
pub enum Built {
    Light(Light),
    Environment(Environment),
}

impl LightDesc {
    /// Checks the values serde cannot; errors name `t`'s file and key.
    pub(crate) fn validate(&self, t: &Table) -> Result<()> {
        match self {
            LightDesc::Directional(l) => l.validate(t),
            LightDesc::Point(l) => l.validate(t),
            LightDesc::Environment(l) => l.validate(t),
            LightDesc::Area(l) => l.validate(t),
        }
    }

    /// The light, with any file it names loaded.
    pub(crate) fn build(&self, t: &Table) -> Result<Built> {
        Ok(match self {
            LightDesc::Directional(l) => Built::Light(Light::Directional(l.build())),
            LightDesc::Point(l) => Built::Light(Light::Point(l.build())),
            LightDesc::Environment(l) => Built::Environment(l.build(t)?),
            LightDesc::Area(l) => Built::Light(Light::Area(l.build())),
        })
    }

    /// A constant environment of `radiance` from every direction.
    pub fn uniform_environment(radiance: f64) -> LightDesc {
        LightDesc::Environment(EnvironmentDesc {
            radiance,
            map: None,
            surroundings: None,
        })
    }

    /// The same light with its generated surroundings turned by `turn`
    /// degrees about up (other lights are returned unchanged).
    pub fn turned(&self, turn: f64) -> LightDesc {
        match self {
            LightDesc::Environment(l) => {
                let mut l = l.clone();
                if let Some(s) = &mut l.surroundings {
                    s.turn = (s.turn + turn).rem_euclid(360.0);
                }
                LightDesc::Environment(l)
            }
            other => other.clone(),
        }
    }

    /// An environment light's `radiance` (its constant, or its map's factor).
    pub fn environment_radiance(&self) -> Option<f64> {
        match self {
            LightDesc::Environment(l) => Some(l.radiance),
            _ => None,
        }
    }

    /// The direction towards a directional light.
    pub fn direction(&self) -> Option<[f64; 3]> {
        match self {
            LightDesc::Directional(l) => Some(l.direction),
            _ => None,
        }
    }

    /// The same light shining from `direction` instead (lights without a
    /// direction are returned unchanged).
    pub fn with_direction(&self, direction: [f64; 3]) -> LightDesc {
        match self {
            LightDesc::Directional(l) => LightDesc::Directional(DirectionalDesc {
                direction,
                ..l.clone()
            }),
            other => other.clone(),
        }
    }
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

    /// A directional light's irradiance and unit direction towards it.
    pub fn directional_irradiance(&self) -> Option<(f32, Vec3A)> {
        match self {
            Light::Directional(l) => Some((l.irradiance, l.direction)),
            _ => None,
        }
    }

    /// The light as an emitter that rays can hit.
    pub fn area(&self) -> Option<Area> {
        match self {
            Light::Area(l) => Some(*l),
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
