//! The method registry and the one pipeline call (view → reconstruct →
//! write → metrics) that the CLI, the demo, the benches and the sweeps use.
//!
//! A method is named and configured by a serde value, the same in TOML
//! sweep files, JSON and on the command line:
//! `{ method = "smith", eta = 1.5, lambda = 0.1, light = "estimate" }`.
//! Options a method does not have are an error naming the option (a typo
//! must not silently run the defaults); options left out take the method's
//! defaults. The configuration actually used is recorded in `run.json`.
//! Adding a method means its file and one line in `methods/mod.rs`.

use crate::input::{Input, Unusable};
use crate::method::Reconstruction;
use crate::methods::{METHODS, MethodConfig};
use crate::output::write_result;
use crate::run_record::RunRecord;
use crate::solver::memory;
use crate::specular::beyond_diffuse::BeyondDiffuse;
use crate::stage;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sfp_core::metrics::{Metrics, evaluate};
use sfp_core::provenance::{self, Software, ViewRecord};
use sfp_core::view::{GroundTruth, View};
use sfp_core::{Error, Mask, Result};
use std::path::Path;
use std::time::Instant;

impl MethodConfig {
    /// The method `name` with its defaults.
    pub fn default_for(name: &str) -> Result<MethodConfig> {
        Self::with_options(name, serde_json::Map::new())
    }

    /// Every method with its defaults.
    pub fn defaults() -> Vec<MethodConfig> {
        METHODS
            .iter()
            .map(|name| Self::default_for(name).expect("registered methods have defaults"))
            .collect()
    }

    /// The method `name` with `options` (option name → value) over its
    /// defaults; an unknown method or option is an error naming it.
    pub fn with_options(
        name: &str,
        options: serde_json::Map<String, serde_json::Value>,
    ) -> Result<MethodConfig> {
        Self::parse(name, serde_json::Value::Object(options))
    }

    /// A configuration from a serde value with a `method` field.
    pub fn from_value(value: serde_json::Value) -> Result<MethodConfig> {
        let serde_json::Value::Object(mut options) = value else {
            return Err(Error::invalid(format!(
                "a method configuration is a table, not {value}"
            )));
        };
        match options.remove("method") {
            Some(serde_json::Value::String(name)) => Self::with_options(&name, options),
            Some(other) => Err(Error::invalid(format!(
                "method = {other}: expected a method name ({})",
                METHODS.join(", ")
            ))),
            None => Err(Error::invalid(format!(
                "method configuration without `method` (one of {})",
                METHODS.join(", ")
            ))),
        }
    }

    /// Short lower-case name of the method.
    pub fn name(&self) -> &'static str {
        self.about().name
    }

    /// The configuration as a serde value (with its `method` field).
    pub fn to_value(&self) -> serde_json::Value {
        let mut value = self.options_value();
        value["method"] = self.name().into();
        value
    }
}

impl Serialize for MethodConfig {
    fn serialize<S: Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        self.to_value().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for MethodConfig {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        let value = serde_json::Value::deserialize(deserializer)?;
        MethodConfig::from_value(value).map_err(serde::de::Error::custom)
    }
}

/// What one pipeline run produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub reconstruction: Reconstruction,
    /// Figures against the view's ground truth, when it has one: the
    /// content of `metrics.json`.
    pub metrics: Option<Metrics>,
    /// Wall time of the reconstruction alone (no I/O), seconds.
    pub seconds: f64,
    /// Mask pixels reconstructed.
    pub pixels: usize,
    /// The mask pixels without usable data (saturated, unlit, non-finite).
    pub unusable: Unusable,
    /// The content of `run.json`, for runs that keep a record (a result
    /// folder, Python); a sweep's in-memory rows skip it.
    pub record: Option<RunRecord>,
}

impl Outcome {
    /// How much of the mask the diffuse model cannot explain, for runs
    /// that keep a record.
    pub fn beyond_diffuse(&self) -> Option<BeyondDiffuse> {
        self.record.as_ref()?.beyond_diffuse
    }
}

/// Reconstructs `view` with `config`, writes the result folder `out`
/// (conventions.md §5) and evaluates it when the view has ground truth
/// (over the view's mask, or the ground truth's non-zero normals).
pub fn run(view: &View, config: &MethodConfig, out: &Path) -> Result<Outcome> {
    stage::enter("reading the polarization");
    run_with_input(view, &Input::from_view(&view.input)?, config, out)
}

/// [`run`] with the view's `input` already prepared: a caller running
/// several methods on one view reads its polarimetry once.
pub fn run_with_input(
    view: &View,
    input: &Input,
    config: &MethodConfig,
    out: &Path,
) -> Result<Outcome> {
    let gt_mask = view.scored_mask();
    let gt = view.gt.as_ref().zip(gt_mask.as_ref());
    let outcome = reconstruct_scored(input, config, gt, Some(ViewRecord::of(view)))?;
    let record = outcome.record.as_ref().expect("kept above");
    let scored = gt.zip(outcome.metrics.as_ref());
    stage::enter("writing the result");
    write_result(out, &outcome.reconstruction, record, &input.mask, scored)?;
    Ok(outcome)
}

/// [`run_with_input`] without a result folder or record: the
/// reconstruction and its metrics in memory only. Sweeps score thousands
/// of noisy inputs and keep pictures of a few; writing a folder per row
/// would dominate their time.
pub fn evaluate_with_input(view: &View, input: &Input, config: &MethodConfig) -> Result<Outcome> {
    let gt_mask = view.scored_mask();
    reconstruct_scored(input, config, view.gt.as_ref().zip(gt_mask.as_ref()), None)
}

/// The one pipeline every caller runs (the CLI, sweeps, the demo, Python):
/// reconstructs `input` with `config`, scores the result against `gt` over
/// its mask, and with the `view` it came from keeps the run's record (the
/// input's diffuse check and the method's record, as `run.json` holds
/// them).
pub fn reconstruct_scored(
    input: &Input,
    config: &MethodConfig,
    gt: Option<(&GroundTruth, &Mask)>,
    view: Option<ViewRecord>,
) -> Result<Outcome> {
    let (reconstruction, seconds) = reconstruct(input, config)?;
    if gt.is_some() {
        stage::enter("scoring");
    }
    let metrics = gt
        .map(|(gt, mask)| score(&reconstruction, gt, mask))
        .transpose()?;
    let unusable = input.unusable();
    // Only runs that keep a record pay for the diffuse check.
    let record = view.map(|view| RunRecord {
        config: config.clone(),
        seconds,
        view,
        software: Software::this(),
        time: provenance::now(),
        beyond_diffuse: Some(BeyondDiffuse::of(input)),
        unusable: Some(unusable),
        run: reconstruction.run.clone(),
    });
    Ok(Outcome {
        reconstruction,
        metrics,
        seconds,
        pixels: input.mask.count(),
        unusable,
        record,
    })
}

/// The figures of conventions.md §4 of `reconstruction` against `gt` over
/// `mask`, with its specular labelling's scores when it made one.
fn score(reconstruction: &Reconstruction, gt: &GroundTruth, mask: &Mask) -> Result<Metrics> {
    Ok(Metrics {
        specular: reconstruction
            .specular
            .as_ref()
            .and_then(|s| s.scores(gt, mask)),
        ..evaluate(&reconstruction.normals, &gt.normals, mask)?
    })
}

/// Runs the method on an input in memory, timing the reconstruction alone;
/// a view too large for the memory there is is refused first.
pub fn reconstruct(input: &Input, config: &MethodConfig) -> Result<(Reconstruction, f64)> {
    let (width, height) = input.size();
    memory::check_reconstruction(width, height)?;
    let method = config.build();
    let start = Instant::now();
    let reconstruction = method.reconstruct(input)?;
    Ok((reconstruction, start.elapsed().as_secs_f64()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::smith::Smith;
    use sfp_core::analytic::{AnalyticScene, Shape};
    use sfp_core::result_folder::ResultFolder;

    #[test]
    fn configurations_round_trip_through_toml_and_json() {
        for config in MethodConfig::defaults() {
            let toml_text = toml::to_string(&config).unwrap();
            let back: MethodConfig = toml::from_str(&toml_text).unwrap();
            assert_eq!(back.to_value(), config.to_value(), "{toml_text}");
            assert_eq!(back.name(), config.name());
        }
        let parsed: MethodConfig =
            toml::from_str("method = \"smith\"\neta = 1.3\nlight = { direction = [0, 0, 1] }")
                .unwrap();
        match parsed {
            MethodConfig::Smith(s) => {
                assert_eq!(s.shared.eta, 1.3);
                assert_eq!(s.lambda, Smith::default().lambda);
            }
            other => panic!("parsed {other:?}"),
        }
    }

    #[test]
    fn unknown_methods_and_options_are_named() {
        let err = MethodConfig::default_for("nope").unwrap_err().to_string();
        assert!(err.contains("nope") && err.contains("smith"), "{err}");
        let mut options = serde_json::Map::new();
        options.insert("lambda".into(), 0.5.into());
        let err = MethodConfig::with_options("atkinson", options)
            .unwrap_err()
            .to_string();
        assert!(err.contains("atkinson") && err.contains("lambda"), "{err}");
    }

    #[test]
    fn values_out_of_range_are_refused_when_parsed() {
        for (method, option, value) in [
            ("smith", "lambda", serde_json::json!(-1.0)),
            ("smsfp", "eta", serde_json::json!(3.5)),
            ("atkinson", "window_radius", serde_json::json!(0)),
            (
                "mahmoud",
                "light",
                serde_json::json!({ "known": { "light": [0, 0, 1], "albedo": 0 } }),
            ),
        ] {
            let options = serde_json::Map::from_iter([(option.to_string(), value)]);
            let err = MethodConfig::with_options(method, options)
                .unwrap_err()
                .to_string();
            assert!(err.contains(method), "{method}.{option}: {err}");
        }
        // Values the step would panic on: named with their range.
        for (option, value, needle) in [
            ("mfcp_params", serde_json::json!({ "scales": [] }), "scales"),
            (
                "mfcp_params",
                serde_json::json!({ "scales": [8, 0] }),
                "scales",
            ),
            ("mfcp_params", serde_json::json!({ "gamma": 0.0 }), "gamma"),
            ("shading_sense", serde_json::json!(-1.0), "shading_sense"),
        ] {
            let options = serde_json::Map::from_iter([(option.to_string(), value)]);
            let err = MethodConfig::with_options("smsfp", options)
                .unwrap_err()
                .to_string();
            let ranged = [">= 0", "> 0", "at least 1"]
                .iter()
                .any(|r| err.contains(r));
            assert!(err.contains(needle) && ranged, "{option}: {err}");
        }
        let smith = MethodConfig::default_for("smith").unwrap();
        assert!(smith.with_shared(|s| s.eta = 3.5).is_err());
        let set = smith.with_shared(|s| s.eta = 1.3).unwrap();
        assert_eq!(set.to_value()["eta"], 1.3);
    }

    #[test]
    fn pipeline_writes_and_scores_every_method() {
        let view = AnalyticScene {
            shape: Shape::Sphere,
            size: 64,
            // Tilted: under a frontal light Mahmoud's shading cannot choose.
            light: [0.3, 0.2, 1.0],
            ..AnalyticScene::default()
        }
        .render()
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        for config in MethodConfig::defaults() {
            let out = dir.path().join(config.name());
            let outcome = run(&view, &config, &out).unwrap();
            let m = outcome.metrics.unwrap();
            assert!(m.mae_deg < 5.0, "{}: {}", config.name(), m.mae_deg);
            let run = RunRecord::read(&ResultFolder::new(&out)).unwrap().unwrap();
            assert_eq!(run.config.to_value(), config.to_value());
            assert_eq!(run.run, outcome.reconstruction.run);
            assert!(out.join("metrics.json").exists());
            // In memory: the same figures, no folder.
            let input = Input::from_view(&view.input).unwrap();
            let scored = evaluate_with_input(&view, &input, &config).unwrap();
            assert_eq!(scored.metrics.unwrap(), m, "{}", config.name());
        }
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            METHODS.len()
        );
    }

    #[test]
    fn a_specular_labelling_is_drawn_and_scored() {
        let mut view = AnalyticScene {
            shape: Shape::Sphere,
            size: 48,
            light: [0.3, 0.2, 1.0],
            ..AnalyticScene::default()
        }
        .render()
        .unwrap();
        // Ground truth of a mixture: inside the disc the specular part
        // holds 60 % of s0 and twice the measured polarization (so it
        // outweighs the diffuse part's).
        let disc = sfp_core::Image::from_fn(48, 48, |x, y| {
            (x as f64 - 24.0).hypot(y as f64 - 24.0) < 10.0
        });
        let gt = view.gt.as_mut().unwrap();
        let [s0, s1, s2] = gt.stokes.clone().unwrap();
        let part = |s: &sfp_core::Image<f32>, k: f32| {
            sfp_core::Image::from_fn(48, 48, |x, y| {
                if *disc.get(x, y) {
                    k * *s.get(x, y)
                } else {
                    0.0
                }
            })
        };
        gt.specular_stokes = Some([part(&s0, 0.6), part(&s1, 2.0), part(&s2, 2.0)]);
        let dir = tempfile::tempdir().unwrap();
        let mask_path = dir.path().join("spec.png");
        sfp_core::io::write_png8(&mask_path, &disc.map(|&d| if d { 255 } else { 0 })).unwrap();
        let mut options = serde_json::Map::new();
        options.insert("specular".into(), mask_path.display().to_string().into());
        let config = MethodConfig::with_options("smith", options).unwrap();
        let out = dir.path().join("result");
        let outcome = run(&view, &config, &out).unwrap();
        let scores = outcome.metrics.unwrap().specular.unwrap();
        assert!(scores.polarization.f1 > 0.95, "{scores:?}");
        // The intensity class is the share of the mixture that explains the
        // data under the method's normals (`specular::share`): inside the
        // disc Smith turned the azimuths, so there the polarization runs
        // across them and is read as mostly specular; outside, diffuse.
        let intensity = scores.intensity;
        assert_eq!(intensity.true_positives, intensity.labelled, "{scores:?}");
        assert!(
            intensity.labelled * 3 > intensity.positives * 2,
            "{scores:?}"
        );
        assert!(out.join(ResultFolder::SPECULAR).exists());
        let share =
            sfp_core::io::read_exr(&out.join(ResultFolder::SPECULAR_SHARE), &["Y"]).unwrap();
        assert!(share[0].data().iter().all(|&f| (0.0..=1.0).contains(&f)));
        let json = std::fs::read_to_string(out.join("metrics.json")).unwrap();
        assert!(
            json.contains("\"polarization\"") && json.contains("\"f1\""),
            "{json}"
        );
        // Off: no picture, no scores.
        let plain = dir.path().join("plain");
        let outcome = run(&view, &MethodConfig::default_for("smith").unwrap(), &plain).unwrap();
        assert!(outcome.metrics.unwrap().specular.is_none());
        assert!(!plain.join(ResultFolder::SPECULAR).exists());
        assert!(!plain.join(ResultFolder::SPECULAR_SHARE).exists());
    }
}
