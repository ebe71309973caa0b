//! `sfp eval`: a prediction (a result folder, or any tool's normal map as
//! a file) scored against a view's ground truth, with the protocol stated.

use crate::exit::CliResult;
use sfp_core::metrics::{Metrics, evaluate};
use sfp_core::prediction::{self, Axes};
use sfp_core::provenance;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::{View, ViewInput};
use sfp_reconstruct::run_record::RunRecord;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// View folder with gt/normals.exr.
    view: PathBuf,
    /// The prediction: a result folder (its normals.exr, .npy or .png), or a
    /// file: .exr (R, G, B), .npy (H×W×3 float32/float64) or .png (8/16-bit,
    /// decoded 2·v/max − 1).
    prediction: PathBuf,
    /// The prediction's frame: ours (x right, y up, z towards the camera),
    /// image (y down, z towards the camera) or opencv (y down, z into the scene).
    #[arg(long, default_value = "ours", value_parser = crate::values::parse_axes)]
    axes: Axes,
    /// Folder for metrics.json and error.png (default: the result folder, or
    /// the prediction file's folder).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print metrics.json instead of the table.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> CliResult {
    let view = View::read(&a.view)?;
    if sfp_core::folder::Kind::of(&a.prediction) == Some(sfp_core::folder::Kind::View) {
        return Err(format!(
            "{}: is a view, not a prediction: the arguments are `sfp eval VIEW PREDICTION`",
            a.prediction.display()
        )
        .into());
    }
    let (file, out) = if a.prediction.is_dir() {
        let result = ResultFolder::new(&a.prediction);
        check_provenance(&result, &view.input)?;
        let file = prediction::in_folder(&a.prediction).ok_or_else(|| {
            format!(
                "{}: no prediction in the folder (expected one of {})",
                a.prediction.display(),
                prediction::FILE_NAMES.join(", ")
            )
        })?;
        (file, a.prediction.clone())
    } else if a.prediction.is_file() {
        let beside = a
            .prediction
            .parent()
            .unwrap_or(Path::new("."))
            .to_path_buf();
        (a.prediction.clone(), beside)
    } else {
        return Err(format!(
            "{}: no such file or folder (expected a result folder or a normals file)",
            a.prediction.display()
        )
        .into());
    };
    let out = a.out.unwrap_or(out);
    // metrics.json and error.png go into OUT: never into a view's data.
    sfp_core::folder::ensure_outside_view_data(&out)?;
    let mask = view
        .scored_mask()
        .ok_or_else(|| match view.problems.first() {
            Some(problem) => format!("no usable ground truth: {problem}"),
            None => format!(
                "{}: no ground truth (gt/normals.exr is absent)",
                a.view.display()
            ),
        })?;
    let mask_from = match view.input.mask {
        Some(_) => "the view's input/mask.png",
        None => "the pixels with a ground-truth normal (the view has no mask)",
    };
    let gt = view.gt.expect("a scored mask comes with ground truth");
    let pred = prediction::read(&file, a.axes)?;
    if pred.size() != mask.size() {
        return Err(format!(
            "{}: is {:?} pixels but the view is {:?}",
            file.display(),
            pred.size(),
            mask.size()
        )
        .into());
    }
    let m = evaluate(&pred, &gt.normals, &mask)?;
    std::fs::create_dir_all(&out).map_err(|e| sfp_core::Error::io(&out, e))?;
    ResultFolder::new(&out).write_evaluation(&pred, &gt.normals, &mask, &m)?;
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&m)?)?;
    } else {
        outln!("{}", protocol(&file, a.axes, mask_from, &m))?;
        outln!("{}", table(&m))?;
        outln!("→ {}", out.join("metrics.json").display())?;
    }
    Ok(())
}

/// How the figures were made (conventions.md §4), printed with them.
fn protocol(file: &Path, axes: Axes, mask_from: &str, m: &Metrics) -> String {
    format!(
        "prediction {} in frame {}
         protocol (conventions.md §4): angular error acos(n̂·n_gt) in degrees, uncapped (0–180°),          over {} pixels: {mask_from}; predictions are normalised to unit length;          {} pixels without a usable prediction (zero or non-finite) count as 90°;          <t° is the share of those pixels under t°",
        file.display(),
        axes.describe(),
        m.pixels,
        m.missing,
    )
}

fn table(m: &Metrics) -> String {
    format!(
        "| MAE | RMSE | median | <11.25° | <22.5° | <30° | pixels | missing |\n\
         |---|---|---|---|---|---|---|---|\n\
         | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {} | {} |",
        m.mae_deg, m.rmse_deg, m.median_deg, m.acc_11_25, m.acc_22_5, m.acc_30, m.pixels, m.missing
    )
}

/// Refuses a result whose `run.json` records another view's input (its
/// content hash or size): scoring a torus result against a sphere view
/// gives a meaningless figure and overwrote the result's metrics. A
/// `run.json` that cannot be read or records no view is refused too; a
/// result without one (another tool's normals) is scored with a warning.
fn check_provenance(result: &ResultFolder, input: &ViewInput) -> CliResult {
    let path = result.run_path();
    if result.read_run::<serde_json::Value>()?.is_none() {
        eprintln!(
            "warning: {} is absent: the result's view cannot be checked; scoring it as made from this view",
            path.display()
        );
        return Ok(());
    }
    let Some(recorded) = RunRecord::read_view(result)? else {
        return Err(format!(
            "{}: records no view (no \"view\" entry): cannot tell which view the result was \
             made from; remove run.json to score a result of another tool",
            path.display()
        )
        .into());
    };
    let recorded_path = recorded.path.as_deref().unwrap_or("path not recorded");
    let (w, h) = input.size();
    if recorded.size != [w, h] {
        return Err(format!(
            "{}: the result was reconstructed from a {}×{} view ({recorded_path}), not this {w}×{h} one",
            path.display(),
            recorded.size[0],
            recorded.size[1],
        )
        .into());
    }
    let hash = &recorded.input_hash;
    if *hash != provenance::input_hash(input) {
        return Err(format!(
            "{}: the result was reconstructed from another view's input ({recorded_path}; input hash {}…), not this view's",
            path.display(),
            &hash[..hash.len().min(12)],
        )
        .into());
    }
    Ok(())
}
