//! `sfp export`: results and views in the formats other code reads.

use crate::exit::CliResult;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::View;
use sfp_core::{export, folder};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A reconstruction folder (→ normals.npy, normals.png 16-bit,
    /// height.npy) or a view folder (→ the per-angle layout pol000/ pol045/
    /// pol090/ pol135/ normal/ mask/, which `sfp import --layout` reads back).
    path: PathBuf,
    /// Output folder (a layout folder may collect many views).
    #[arg(long)]
    out: PathBuf,
    /// Name of the view inside the layout (default: the view folder's name).
    #[arg(long)]
    name: Option<String>,
}

pub fn run(a: Args) -> CliResult {
    let result = ResultFolder::new(&a.path);
    if result.normals_path().is_file() && result.height_path().is_file() {
        export::export_result(&a.path, &a.out)?;
        outln!(
            "exported the reconstruction {} to {}",
            a.path.display(),
            a.out.display()
        )?;
        return Ok(());
    }
    if folder::is_view(&a.path) {
        let view = View::read(&a.path)?;
        let name = match &a.name {
            Some(n) => n.clone(),
            None => a
                .path
                .canonicalize()
                .ok()
                .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .unwrap_or_else(|| "view".to_string()),
        };
        export::export_layout(&view, &name, &a.out)?;
        outln!(
            "exported the view {} as {name} into {}",
            a.path.display(),
            a.out.display()
        )?;
        return Ok(());
    }
    Err(format!(
        "{}: neither a reconstruction (normals.exr, height.exr) nor a view (input/)",
        a.path.display()
    )
    .into())
}
