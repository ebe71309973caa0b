//! `sfp eval`.

use crate::exit::CliResult;
use sfp_core::metrics::evaluate;
use sfp_core::provenance;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::{View, ViewInput};
use sfp_reconstruct::run_record::RunRecord;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// View folder with gt/normals.exr.
    view: PathBuf,
    /// Reconstruction folder with normals.exr; metrics.json and error.png are written here.
    result: PathBuf,
}

pub fn run(a: Args) -> CliResult {
    // metrics.json and error.png go into RESULT: never into a view's gt/.
    sfp_core::folder::ensure_outside_view_data(&a.result)?;
    let view = View::read(&a.view)?;
    if sfp_core::folder::Kind::of(&a.result) == Some(sfp_core::folder::Kind::View) {
        return Err(format!(
            "{}: is a view, not a reconstruction: the arguments are `sfp eval VIEW RESULT`",
            a.result.display()
        )
        .into());
    }
    if !a.result.is_dir() {
        return Err(format!(
            "{}: not a folder (expected a reconstruction folder with normals.exr)",
            a.result.display()
        )
        .into());
    }
    let result = ResultFolder::new(&a.result);
    check_provenance(&result, &view.input)?;
    let gt = view.gt.ok_or_else(|| match view.problems.first() {
        Some(problem) => format!("no usable ground truth: {problem}"),
        None => format!(
            "{}: no ground truth (gt/normals.exr is absent)",
            a.view.display()
        ),
    })?;
    let mask = view
        .input
        .mask
        .unwrap_or_else(|| gt.normals.map(|n| *n != [0.0; 3]));
    let pred = result.read_normals()?;
    if pred.size() != mask.size() {
        return Err(format!(
            "{}: is {:?} pixels but the view is {:?}",
            result.normals_path().display(),
            pred.size(),
            mask.size()
        )
        .into());
    }
    let m = evaluate(&pred, &gt.normals, &mask)?;
    result.write_evaluation(&pred, &gt.normals, &mask, &m)?;
    outln!("{}", serde_json::to_string_pretty(&m)?)?;
    Ok(())
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
