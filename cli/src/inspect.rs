//! `sfp inspect`.

use crate::exit::CliResult;
use sfp_core::view::View;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// View folder.
    view: PathBuf,
    /// Where to write the preview pictures (default: VIEW/preview).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(a: Args) -> CliResult {
    let view = View::read(&a.view)?;
    let summary = sfp_core::inspect::summarize(&view);
    outln!("{}", serde_json::to_string_pretty(&summary)?)?;
    let out = a.out.unwrap_or_else(|| a.view.join("preview"));
    view.write_previews(&out)?;
    eprintln!("previews in {}", out.display());
    Ok(())
}
