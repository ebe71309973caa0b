//! `sfp reconstruct`: one view, or every view of a dataset (results in
//! `OUT/<view>/<method>/`, tables in `OUT/summary.md` and `summary.csv`).

use crate::exit::CliResult;
use crate::progress::Progress;
use crate::values::parse_vec3;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{Map, Value, json};
use sfp_benchmarks::dataset::{self, DatasetView, Target};
use sfp_benchmarks::report::summary;
use sfp_core::collection::{self, Collection};
use sfp_core::view::View;
use sfp_reconstruct::input::UNUSABLE_WARN_SHARE;
use sfp_reconstruct::methods::{self, METHODS, MethodConfig};
use sfp_reconstruct::{registry, stage};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// `--method all`: every registered method.
const ALL: &str = "all";

/// `--help` ends with every method's options, defaults and meanings (from
/// the methods' declarations, as the README's table).
#[derive(clap::Args)]
#[command(after_long_help = sfp_reconstruct::listing::text())]
pub struct Args {
    /// View folder (reads input/; gt/ only to write metrics.json), or a
    /// dataset folder (dataset.json, or view folders) to reconstruct every view.
    path: PathBuf,
    /// Reconstruction method, or `all` for every method with its defaults.
    #[arg(long, default_value = "smsfp", value_parser = clap::builder::PossibleValuesParser::new(METHODS.iter().copied().chain([ALL])))]
    method: String,
    /// Output folder: the result folder of one view and method; otherwise
    /// `<view>/<method>/` result folders and summary.md, summary.csv.
    #[arg(long)]
    out: PathBuf,
    /// Method configuration file (TOML: `eta = 1.3`, `lambda = 0.2`, …, with
    /// or without `method = "…"`); command-line options override it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Refractive index assumed by the method (default: the method's own).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::values::parse_finite)]
    eta: Option<f64>,
    /// Known direction towards the light (camera frame); estimated when absent.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    light: Option<[f64; 3]>,
    /// Estimate ambient + directional (first-order spherical-harmonic) lighting.
    #[arg(long, conflicts_with = "light")]
    ambient: bool,
    /// Laplacian smoothness weight (smith, smsfp).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::values::parse_finite)]
    lambda: Option<f64>,
    /// Seed of the light estimator's starting lights.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::values::parse_whole::<u64>)]
    seed: Option<u64>,
    /// Any other method option, as NAME=VALUE with a TOML value (repeatable),
    /// e.g. `--set parg=false`; `--help` lists every method's options.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
}

/// The options given: the file's, then the command line's over them.
fn options(a: &Args) -> Result<Map<String, Value>, String> {
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
                    // With `all` too: one file configures one method.
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
    Ok(options)
}

/// A flag given for one method that has no such option is named with the
/// methods that have it (`--ambient` with atkinson said "unknown field
/// `light`").
fn flags_fit(a: &Args) -> Result<(), String> {
    let given = [
        ("--eta", "eta", a.eta.is_some()),
        ("--light", "light", a.light.is_some()),
        ("--ambient", "light", a.ambient),
        ("--lambda", "lambda", a.lambda.is_some()),
        ("--seed", "seed", a.seed.is_some()),
    ];
    let has = methods::has_option;
    for (flag, key, _) in given.into_iter().filter(|g| g.2) {
        if !has(&a.method, key) {
            let with: Vec<&str> = METHODS.iter().copied().filter(|m| has(m, key)).collect();
            return Err(format!(
                "{flag}: {} has no `{key}` option (the methods that have it: {})",
                a.method,
                with.join(", ")
            ));
        }
    }
    Ok(())
}

/// The method configurations: each method's defaults, then the file, then
/// the command line. With one method, options it does not have are refused
/// by name. With `all`, an option goes to the methods that have it (a note
/// names the others); one that no method has is refused.
fn configs(a: &Args) -> Result<Vec<MethodConfig>, String> {
    let options = options(a)?;
    if a.method != ALL {
        flags_fit(a)?;
        let config = MethodConfig::with_options(&a.method, options).map_err(|e| format!("{e}"))?;
        return Ok(vec![config]);
    }
    let mut configs = Vec::new();
    let mut without: Vec<(&str, Vec<&str>)> =
        options.keys().map(|k| (k.as_str(), vec![])).collect();
    for name in METHODS {
        let mut own = Map::new();
        for ((key, value), (_, missing)) in options.iter().zip(&mut without) {
            if methods::has_option(name, key) {
                own.insert(key.clone(), value.clone());
            } else {
                missing.push(name);
            }
        }
        configs.push(MethodConfig::with_options(name, own).map_err(|e| format!("{e}"))?);
    }
    for (key, missing) in without {
        if missing.len() == METHODS.len() {
            return Err(format!(
                "option '{key}' is not an option of any method ({})",
                METHODS.join(", ")
            ));
        }
        if !missing.is_empty() {
            eprintln!(
                "note: option '{key}' not set for {} (no such option there)",
                missing.join(", ")
            );
        }
    }
    Ok(configs)
}

pub fn run(a: Args) -> CliResult {
    let configs = configs(&a)?;
    let views = match dataset::classify(&a.path)? {
        Target::View if configs.len() == 1 => return run_view(&a, &configs[0]),
        // Several methods on one view: a dataset of that view.
        Target::View => vec![DatasetView::lone(&a.path)],
        Target::Dataset(views) => views,
    };
    run_dataset(&a, &views, &configs)
}

/// One view, one method: `--out` is the result folder.
fn run_view(a: &Args, config: &MethodConfig) -> CliResult {
    let view = View::read(&a.path)?;
    for problem in &view.problems {
        eprintln!("warning: ground truth not used: {problem}");
    }
    // The step the method is in, with the elapsed time (a 1224×1024
    // capture takes 15–23 s): a spinner on a terminal, a line per step in a
    // log or pipe, where a spinner draws nothing.
    let spinner = ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("valid progress template"),
    );
    let head = format!("{}: {}", config.name(), a.path.display());
    spinner.set_message(head.clone());
    spinner.enable_steady_tick(Duration::from_millis(120));
    let (shown, start) = (spinner.clone(), Instant::now());
    let terminal = std::io::stderr().is_terminal();
    let outcome = stage::listen(
        move |step| {
            if terminal {
                shown.set_message(format!("{head}: {step}"));
            } else {
                eprintln!("{head}: {step} [{:.1} s]", start.elapsed().as_secs_f64());
            }
        },
        || registry::run(&view, config, &a.out),
    );
    spinner.finish_and_clear();
    // A method's complaint names the view; the system's refusal keeps its
    // kind (and so its exit code).
    let outcome = outcome.map_err(|e| -> Box<dyn std::error::Error> {
        match e {
            sfp_core::Error::Io { .. } => e.into(),
            e => format!("{}: {e}", a.path.display()).into(),
        }
    })?;
    outln!(
        "{} reconstructed {} pixels in {:.2} s → {}",
        config.name(),
        outcome.pixels,
        outcome.seconds,
        a.out.display()
    )?;
    for warning in &outcome.reconstruction.run.warnings {
        eprintln!("warning: {}: {warning}", a.path.display());
    }
    let unusable = outcome.unusable;
    if unusable.share > UNUSABLE_WARN_SHARE {
        eprintln!(
            "warning: {}: {unusable}: the normals there are guesses and the figures count them (run.json: unusable)",
            a.path.display()
        );
    }
    // With `specular` off the method read every pixel as diffuse.
    let specular_off = outcome.reconstruction.specular.is_none();
    if let Some(warning) = outcome.beyond_diffuse().and_then(|b| b.warning())
        && specular_off
    {
        eprintln!("warning: {}: {warning}", a.path.display());
    }
    if let Some(m) = outcome.metrics {
        outln!("{}", serde_json::to_string_pretty(&m)?)?;
    }
    Ok(())
}

/// Every view × every method, then the summary; failed runs are listed in
/// it and make the exit code non-zero after the others have run.
fn run_dataset(a: &Args, views: &[DatasetView], configs: &[MethodConfig]) -> CliResult {
    let start = Instant::now();
    let _claim = collection::claim(&a.out, Collection::Reconstructions)?;
    let bar = Progress::new(
        (views.len() * configs.len()) as u64,
        "reconstructing {bar:40} {pos}/{len} runs {msg} [{elapsed} < {eta}]",
        "runs",
    );
    bar.bar().enable_steady_tick(Duration::from_millis(250));
    let name = summary::dataset_name(&a.path);
    let runs = dataset::run_all(&name, views, configs, &a.out, &|done, _, what| {
        bar.set(done as u64, None, what);
    });
    bar.finish();
    summary::write_dataset(&a.out, &a.path, configs, &runs.rows, &runs.timings)?;
    match summary::method_means_table(&runs.rows) {
        Some(means) => out!("{means}")?,
        None => outln!("no view has ground truth: timings only")?,
    }
    let failed = runs.rows.iter().filter(|r| r.error.is_some()).count();
    outln!(
        "{} views × {} methods in {:.1} s → {}",
        views.len(),
        configs.len(),
        start.elapsed().as_secs_f64(),
        a.out.join("summary.md").display()
    )?;
    if failed > 0 {
        return Err(format!(
            "{failed} of {} runs failed (messages in {})",
            runs.rows.len(),
            a.out.join("summary.md").display()
        )
        .into());
    }
    Ok(())
}
