//! `sfp demo`: the main job.

use crate::exit::CliResult;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Image width and height of the views: N, or NxN.
    #[arg(long, default_value = "256", value_parser = crate::values::parse_square_size, allow_negative_numbers = true)]
    size: usize,
}

pub fn run(a: Args) -> CliResult {
    let start = Instant::now();
    let bar = ProgressBar::new(1);
    bar.set_style(ProgressStyle::with_template(
        "{bar:30} {pos}/{len} {msg} [{elapsed}]",
    )?);
    sfp_benchmarks::demo::run(&a.out, a.size, &|done, total, name| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(name.to_string());
    })?;
    bar.finish_and_clear();
    let summary = a.out.join("summary.md");
    outln!("{}", std::fs::read_to_string(&summary)?)?;
    outln!(
        "demo finished in {:.1} s; results in {}",
        start.elapsed().as_secs_f64(),
        a.out.display()
    )?;
    Ok(())
}
