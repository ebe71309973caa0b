//! The results model: one [`Row`] of figures per (view, axis values, method,
//! seed) reconstruction, whether a sweep, the demo or a run over a dataset
//! made it. `results.jsonl` holds one [`Row`] per line and `results.csv` the
//! same rows flattened; times live apart in `timings.csv` ([`Timing`]) so
//! that re-running a sweep gives byte-identical results.

use serde::{Deserialize, Serialize};
use sfp_core::metrics::Metrics;
use std::collections::BTreeMap;

/// The value of one swept axis: a number (noise σ, η, elevation in degrees)
/// or a name (a light rig, `on`/`off`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum AxisValue {
    Number(f64),
    Text(String),
}

/// Numbers in their shortest exact form (`1.5`, `20000`), names as they are.
impl std::fmt::Display for AxisValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AxisValue::Number(v) => write!(f, "{v}"),
            AxisValue::Text(t) => f.write_str(t),
        }
    }
}

/// The figures of one reconstruction in a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Stable identity of the row: a hash of (view, axes, method label,
    /// seed), so resuming and merging shards can tell rows apart.
    pub key: String,
    /// Group the view belongs to (a dataset preset, `analytic`, a folder
    /// name): the paper's Table 1 has one block per dataset.
    pub dataset: String,
    /// View name, unique within `dataset`.
    pub view: String,
    /// Object the view shows (per-object tables).
    pub object: String,
    /// Swept axis values of this row, by axis name (e.g. `noise_sigma`,
    /// `eta`, `light_elevation_deg`, `specular`, `texture`, `method_eta`).
    pub axes: BTreeMap<String, AxisValue>,
    /// Method label as the sweep file names it (e.g. `smsfp`,
    /// `smsfp-no-parg`, `smith-true-eta`, a command method's `name`).
    pub method: String,
    /// The method's full configuration (a serialised `MethodConfig`; a
    /// command method's `command`, `axes` and `timeout_s`).
    pub config: serde_json::Value,
    /// Noise seed (the exposure of the cached noise-free render).
    pub seed: u64,
    /// Figures against ground truth; `None` for views without it.
    pub metrics: Option<Metrics>,
    /// Why the row has no result, when the reconstruction failed.
    pub error: Option<String>,
    /// Folder of the noise-free view this row was exposed from, relative to
    /// the sweep's output folder when inside it.
    pub view_dir: String,
    /// Result folder kept for the report's picture grids (relative to the
    /// sweep's output folder), for the rows the sweep keeps pictures of.
    pub pictures: Option<String>,
    /// What the method estimated besides the normals, against the view's
    /// truth; `None` for methods that estimate neither.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimates: Option<Estimates>,
    /// A command method's exit code, when its process exited (`None` for
    /// built-in methods, a command killed on its timeout or never started).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exit_status: Option<i32>,
    /// The last lines of a failed command method's stderr.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stderr_tail: Option<String>,
}

/// A method's estimates of the scene, scored against the view's truth
/// (`meta.json`: its `eta` and key light).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Estimates {
    /// The whole object's estimated refractive index (SMSfP's `eta.initial`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta: Option<f64>,
    /// The view's true refractive index, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta_true: Option<f64>,
    /// Angle in degrees between the kept light direction and the true key
    /// light's, when both are known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light_error_deg: Option<f64>,
}

impl Estimates {
    /// The estimates of a run's `record` against the truth in `meta`;
    /// `None` when the method estimated neither.
    pub fn of(
        record: &sfp_reconstruct::method_record::MethodRecord,
        meta: Option<&sfp_core::view::Meta>,
    ) -> Option<Estimates> {
        let eta = record.estimated_eta();
        let light = record.light_direction();
        if eta.is_none() && light.is_none() {
            return None;
        }
        let truth = meta.and_then(|m| m.light);
        let light_error_deg = light.zip(truth).and_then(|(l, t)| {
            let norm = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
            (norm > 0.0).then(|| {
                let c = (l[0] * t[0] + l[1] * t[1] + l[2] * t[2]) / norm;
                c.clamp(-1.0, 1.0).acos().to_degrees()
            })
        });
        Some(Estimates {
            eta,
            eta_true: meta.and_then(|m| m.eta),
            light_error_deg,
        })
    }
}

/// Wall times of one row, seconds (`timings.csv`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub key: String,
    pub method: String,
    /// Mask pixels reconstructed.
    pub pixels: usize,
    /// Exposing the noise-free Stokes with this row's seed.
    pub noise_seconds: f64,
    /// The reconstruction alone.
    pub reconstruct_seconds: f64,
    /// Everything else the row cost: metrics, writing, bookkeeping.
    pub overhead_seconds: f64,
}
