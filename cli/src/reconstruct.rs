//! `sfp reconstruct`.

use crate::{CliResult, parse_vec3};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{Map, Value, json};
use sfp_core::view::View;
use sfp_reconstruct::MethodConfig;
use sfp_reconstruct::registry::{self, METHODS};
use std::path::PathBuf;
use std::time::Duration;

#[derive(clap::Args)]
pub struct Args {
    /// View folder (reads input/; gt/ only to write metrics.json).
    view: PathBuf,
    /// Reconstruction method.
    #[arg(long, default_value = "smith", value_parser = clap::builder::PossibleValuesParser::new(METHODS))]
    method: String,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Method configuration file (TOML: `eta = 1.3`, `lambda = 0.2`, …, with
    /// or without `method = "…"`); command-line options override it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Refractive index assumed by the method (default: the method's own).
    #[arg(long, allow_hyphen_values = true)]
    eta: Option<f64>,
    /// Known direction towards the light (camera frame); estimated when absent.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    light: Option<[f64; 3]>,
    /// Estimate ambient + directional (first-order spherical-harmonic) lighting.
    #[arg(long, conflicts_with = "light")]
    ambient: bool,
    /// Laplacian smoothness weight (smith, smsfp).
    #[arg(long, allow_hyphen_values = true)]
    lambda: Option<f64>,
    /// Seed of the light estimator's starting lights.
    #[arg(long)]
    seed: Option<u64>,
    /// Any other method option, as NAME=VALUE with a TOML value (repeatable),
    /// e.g. `--set parg=false`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
}

/// The method configuration: the method's defaults, then the file, then the
/// command line. Options the method does not have are refused by name.
fn config(a: &Args) -> Result<MethodConfig, String> {
    let mut options = Map::new();
    if let Some(path) = &a.config {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        let table: Value = toml::from_str::<toml::Table>(&text)
            .map_err(|e| format!("{}: {e}", path.display()))
            .and_then(|t| serde_json::to_value(t).map_err(|e| e.to_string()))?;
        let Value::Object(table) = table else {
            unreachable!("a TOML table is an object")
        };
        for (key, value) in table {
            if key == "method" {
                if value.as_str() != Some(&a.method) {
                    return Err(format!(
                        "{}: method = {value} does not match --method {}",
                        path.display(),
                        a.method
                    ));
                }
                continue;
            }
            options.insert(key, value);
        }
    }
    if let Some(eta) = a.eta {
        options.insert("eta".into(), eta.into());
    }
    match (a.light, a.ambient) {
        (Some(d), _) => {
            options.insert("light".into(), json!({ "direction": d }));
        }
        (None, true) => {
            options.insert("light".into(), "estimate_ambient".into());
        }
        (None, false) => {}
    }
    if let Some(lambda) = a.lambda {
        options.insert("lambda".into(), lambda.into());
    }
    if let Some(seed) = a.seed {
        options.insert("seed".into(), seed.into());
    }
    for item in &a.set {
        let (key, text) = item
            .split_once('=')
            .ok_or_else(|| format!("--set {item}: expected NAME=VALUE"))?;
        let value: Value = toml::from_str::<toml::Table>(&format!("v = {text}"))
            .ok()
            .and_then(|t| serde_json::to_value(&t["v"]).ok())
            .unwrap_or_else(|| Value::String(text.to_string()));
        options.insert(key.trim().to_string(), value);
    }
    MethodConfig::with_options(&a.method, options).map_err(|e| format!("{e}"))
}

pub fn run(a: Args) -> CliResult {
    let config = config(&a)?;
    let view = View::read(&a.view)?;
    // A spinner with the elapsed time: large captures take a minute.
    let spinner = ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("valid progress template"),
    );
    spinner.set_message(format!("{}: {}", config.name(), a.view.display()));
    spinner.enable_steady_tick(Duration::from_millis(120));
    let outcome = registry::run(&view, &config, &a.out);
    spinner.finish_and_clear();
    let outcome = outcome.map_err(|e| format!("{}: {e}", a.view.display()))?;
    println!(
        "{} reconstructed {} pixels in {:.2} s → {}",
        config.name(),
        outcome.pixels,
        outcome.seconds,
        a.out.display()
    );
    if let Some(m) = outcome.metrics {
        println!("{}", serde_json::to_string_pretty(&m)?);
    }
    Ok(())
}
