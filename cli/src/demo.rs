//! `sfp demo`: the main job.

use crate::exit::CliResult;
use crate::progress::Progress;
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
    let bar = Progress::new(1, "{bar:30} {pos}/{len} {msg} [{elapsed}]", "steps");
    sfp_benchmarks::demo::run(&a.out, a.size, &|done, total, name| {
        bar.set(done as u64, Some(total as u64), name);
    })?;
    bar.finish();
    let summary = a.out.join("summary.md");
    outln!("{}", std::fs::read_to_string(&summary)?)?;
    outln!(
        "demo finished in {:.1} s; open {} (the report: who won, tables, pictures)",
        start.elapsed().as_secs_f64(),
        a.out.join("index.html").display()
    )?;
    Ok(())
}
