//! `sfp eval`.

use crate::CliResult;
use sfp_core::metrics::write_evaluation;
use sfp_core::view::{View, read_normals};
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
    let pred_path = a.result.join("normals.exr");
    let pred = read_normals(&pred_path)?;
    if pred.size() != mask.size() {
        return Err(format!(
            "{}: is {:?} pixels but the view is {:?}",
            pred_path.display(),
            pred.size(),
            mask.size()
        )
        .into());
    }
    let m = write_evaluation(&a.result, &pred, &gt.normals, &mask)?;
    println!("{}", serde_json::to_string_pretty(&m)?);
    Ok(())
}
