//! What a sweep axis is: its declaration ([`Axis`]) and what it changes
//! ([`Change`]), the vocabulary every family file declares its axes in.

use super::light_pose::LightPose;
use crate::row::AxisValue;
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

impl Axis {
    pub fn kind(&self) -> AxisKind {
        match self.change {
            Change::Render { .. } => AxisKind::Render,
            Change::Noise(_) => AxisKind::Noise,
            Change::Method { .. } => AxisKind::Method,
        }
    }
}

/// A number value (text values are never a number axis's: `accepts`
/// checked them).
pub(super) fn number(value: &AxisValue) -> Option<f64> {
    match value {
        AxisValue::Number(x) => Some(*x),
        AxisValue::Text(_) => None,
    }
}

/// A text value.
pub(super) fn text(value: &AxisValue) -> Option<&str> {
    match value {
        AxisValue::Number(_) => None,
        AxisValue::Text(t) => Some(t),
    }
}
