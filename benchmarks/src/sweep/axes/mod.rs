//! The axes a sweep may name, each declared once: its key, what its values
//! are, what it changes (a render, an exposure or a method's
//! configuration) and how the report labels it. The sweep file, the plan
//! and the report read this registry; adding an axis is its declaration in
//! the file of its family and one line in [`AXES`].

pub mod light;
pub mod material;
pub mod method;
pub mod noise;

use crate::row::AxisValue;
use light::LightPose;
use sfp_core::analytic::AnalyticScene;
use sfp_reconstruct::shared_options::SharedOptions;
use sfp_renderer::scene::{SceneDesc, SensorDesc};

/// One sweep axis.
pub struct Axis {
    /// The key in a sweep's `[axes]` table, a row's axis name.
    pub key: &'static str,
    /// An earlier key still read, with a note that it is deprecated.
    pub old_key: Option<&'static str>,
    /// What a value is, in words (error messages).
    pub meaning: &'static str,
    /// Whether a value (of the file, already typed) is one of the axis's.
    pub accepts: fn(&AxisValue) -> bool,
    /// The report's name of the axis and its unit (empty: unitless or text).
    pub label: &'static str,
    pub unit: &'static str,
    pub change: Change,
}

/// What an axis changes, which decides where it can apply and what a new
/// value costs.
pub enum Change {
    /// The scene: a new value is a new noise-free render.
    Render {
        /// Sets a value on a rendered view's scene.
        scene: fn(&mut SceneChange, &AxisValue),
        /// Sets it on an analytic view; `None`: analytic views lack it.
        analytic: Option<fn(&mut AnalyticChange, &AxisValue)>,
    },
    /// The sensor: a new value is a new exposure of the same render.
    Noise(fn(&mut SensorDesc, &AxisValue)),
    /// The method's assumptions: a new value is a new reconstruction only.
    Method {
        /// The shared method option it sets, which a `[[methods]]` entry
        /// then must leave out.
        option: &'static str,
        /// Sets a value, given the view's true η (or why it has none).
        set: fn(&mut SharedOptions, &AxisValue, &TrueEta) -> Result<(), String>,
    },
}

/// A view's true η, or why it has none (ambiguous, unknown): what a
/// method axis may ask for.
pub type TrueEta = Result<f64, String>;

/// An axis's [`Change`] without its functions: how a plan groups rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisKind {
    Render,
    Noise,
    Method,
}

/// A rendered view's scene while the render axes of one point change it;
/// the light axes gather the key light's pose, placed once all have run.
pub struct SceneChange {
    pub desc: SceneDesc,
    pub light: LightPose,
}

/// An analytic view while the render axes of one point change it.
pub struct AnalyticChange {
    pub scene: AnalyticScene,
    pub light: LightPose,
}

/// Every axis, in name order.
pub const AXES: &[&Axis] = &[
    &material::ETA,
    &light::LIGHT,
    &light::LIGHT_AZIMUTH_DEG,
    &light::LIGHT_ELEVATION_DEG,
    &method::METHOD_ETA,
    &noise::NOISE_FULL_WELL,
    &noise::NOISE_READ_SIGMA,
    &material::ROUGHNESS,
    &material::SPECULAR_WEIGHT,
    &material::TEXTURE,
];

impl Axis {
    pub fn kind(&self) -> AxisKind {
        match self.change {
            Change::Render { .. } => AxisKind::Render,
            Change::Noise(_) => AxisKind::Noise,
            Change::Method { .. } => AxisKind::Method,
        }
    }
}

/// The axis of key `key`.
pub fn axis(key: &str) -> Option<&'static Axis> {
    AXES.iter().copied().find(|a| a.key == key)
}

/// The axis `key` names in a sweep file, and whether `key` is its old,
/// deprecated key.
pub fn named(key: &str) -> Option<(&'static Axis, bool)> {
    axis(key).map(|a| (a, false)).or_else(|| {
        AXES.iter()
            .copied()
            .find(|a| a.old_key == Some(key))
            .map(|a| (a, true))
    })
}

/// The keys of every axis, for an error naming the known ones.
pub fn keys() -> Vec<&'static str> {
    AXES.iter().map(|a| a.key).collect()
}

/// A number value (text values are never a number axis's: `accepts`
/// checked them).
fn number(value: &AxisValue) -> Option<f64> {
    match value {
        AxisValue::Number(x) => Some(*x),
        AxisValue::Text(_) => None,
    }
}

/// A text value.
fn text(value: &AxisValue) -> Option<&str> {
    match value {
        AxisValue::Number(_) => None,
        AxisValue::Text(t) => Some(t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_sorted_and_documented() {
        let keys = keys();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "{keys:?}");
        let readme = include_str!("../../../README.md");
        for a in AXES {
            assert!(
                readme.contains(&format!("| `{}` |", a.key)),
                "{} is not in benchmarks/README.md's axis table",
                a.key
            );
            if let Some(old) = a.old_key {
                assert!(axis(old).is_none(), "{old} is an axis and an old key");
            }
        }
    }

    #[test]
    fn old_keys_name_their_axis() {
        let (a, old) = named("specular").unwrap();
        assert_eq!((a.key, old), ("specular_weight", true));
        let (a, old) = named("specular_weight").unwrap();
        assert_eq!((a.key, old), ("specular_weight", false));
        assert!(named("wobble").is_none());
    }
}
