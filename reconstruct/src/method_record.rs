//! What a method reports about one reconstruction: the method's part of
//! `run.json` ([`crate::run_record::RunRecord`] adds the configuration, the
//! time and where the input came from). The parts every method shares are
//! typed here; what only one method reports is its own.

use crate::input::Input;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::collections::BTreeMap;

/// A method's record of its run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MethodRecord {
    /// The method's name (its declaration's).
    pub method: String,
    /// Seconds per step, by the method's step names.
    pub timings: BTreeMap<String, f64>,
    /// The light the method used, when it estimates or takes one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light: Option<LightRecord>,
    pub counts: Counts,
    /// What the method found the data leave undetermined, in words for the
    /// user (`sfp reconstruct` prints them; absent when none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// What only this method records (SMSfP: the refractive-index search,
    /// segmentation, regions, noise).
    #[serde(flatten)]
    pub own: Map<String, Value>,
}

/// The light a method used: the candidates it solved with and the one kept.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LightRecord {
    /// Where it came from (`estimated`, `known_direction`, `known`), for
    /// methods that take a known light as a candidate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The convex/concave pair of an estimated light, or the one light.
    pub candidates: Vec<LightCandidate>,
    /// Index into `candidates` of the light kept.
    pub chosen: usize,
    /// Agreement of each candidate's normals with the occluding contours,
    /// for methods that score the pair as a whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub boundary_agreement: Option<Vec<f64>>,
    /// RMS residual of the light fit (intensities in units of
    /// `intensity_scale`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_residual: Option<f64>,
    /// Iterations and starting lights of the estimator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub starts: Option<usize>,
    /// The robust maximum intensity the light is expressed against.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity_scale: Option<f64>,
    /// The light could not be estimated and a frontal one was used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frontal_fallback: Option<bool>,
}

/// One light a method solved with.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LightCandidate {
    /// Direction × irradiance (× albedo when folded in), camera frame.
    pub vector: [f64; 3],
    /// Unit direction towards the light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
    /// Ambient term of a first-order spherical-harmonic light.
    pub ambient: f64,
    /// Albedo the intensities were divided by.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<f64>,
    /// Agreement of this candidate's normals with the contours, when scored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub boundary_agreement: Option<f64>,
}

impl MethodRecord {
    /// A record a method built as a JSON value with the fields above.
    pub fn from_json(value: Value) -> MethodRecord {
        serde_json::from_value(value).expect("a method's record has the shared fields")
    }

    /// The refractive index the method estimated for the whole object, when
    /// it estimates one (SMSfP: the search of its step 2, `eta.initial`, which
    /// every region's refinement stays within `eta_band` of).
    pub fn estimated_eta(&self) -> Option<f64> {
        self.own.get("eta")?.get("initial")?.as_f64()
    }

    /// The unit direction of the light the method kept, when it used one.
    pub fn light_direction(&self) -> Option<[f64; 3]> {
        let c = self.light.as_ref()?.chosen();
        let v = c.direction.unwrap_or(c.vector);
        let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (norm > 0.0 && norm.is_finite()).then(|| v.map(|x| x / norm))
    }
}

impl Counts {
    /// The three counts every method gives, of its `input`.
    pub fn of(input: &Input) -> Counts {
        Counts {
            pixels: input.mask.count(),
            dark_pixels: input.dark.count(),
            nonfinite_dropped: input.dropped_nonfinite,
            ..Counts::default()
        }
    }
}

impl LightRecord {
    /// The candidate kept.
    pub fn chosen(&self) -> &LightCandidate {
        &self.candidates[self.chosen]
    }
}

/// What a method counted; every method counts the first three.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    /// Mask pixels reconstructed.
    pub pixels: usize,
    /// Mask pixels without a usable polarization signal (`Input::dark`).
    pub dark_pixels: usize,
    /// Non-finite input samples dropped from the mask.
    pub nonfinite_dropped: usize,
    /// Mask pixels the light does not reach (`Input::unlit`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unlit_pixels: Option<usize>,
    /// Pixels whose DoP exceeded the diffuse model's maximum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dop_clamped: Option<usize>,
    /// Connected mask components.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub components: Option<usize>,
    /// What only this method counts (seeds, rows, per-pixel outcomes…).
    #[serde(flatten)]
    pub own: BTreeMap<String, Value>,
}
