//! `sfp bench`: run a sweep file (`sfp bench SWEEP.toml --out DIR [--shard
//! K/N]`), merge shards (`sfp bench merge DIR... --out DIR`), or write the
//! report of a sweep folder again (`sfp bench report DIR`). A whole sweep
//! and a merge end with the report (`index.html`, `report.md`). Format and
//! cluster use: `benchmarks/README.md`.

use crate::exit::CliResult;
use crate::progress::Progress;
use sfp_benchmarks::report;
use sfp_benchmarks::sweep::{self, file::Sweep, shard::Shard};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(clap::Subcommand)]
enum Command {
    /// Merge the folders of a sweep's shards into one (rows in plan order) and write its report.
    Merge(MergeArgs),
    /// Write the report of a sweep folder (index.html, report.md, plots, grids).
    Report(ReportArgs),
}

#[derive(clap::Args)]
struct ReportArgs {
    /// Sweep folder (with results.jsonl).
    dir: PathBuf,
}

#[derive(clap::Args)]
struct RunArgs {
    /// Sweep file (TOML): views, axes, methods, seeds.
    #[arg(required = true)]
    sweep: Option<PathBuf>,
    /// Output folder; re-running the same command resumes it.
    #[arg(long, required = true)]
    out: Option<PathBuf>,
    /// Run only shard K of N (1 ≤ K ≤ N), e.g. one job-array task.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
}

#[derive(clap::Args)]
struct MergeArgs {
    /// Sweep folders of the shards.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Merged folder.
    #[arg(long)]
    out: PathBuf,
    /// Refuse to merge when a row of the sweep is in none of the folders
    /// (a failed or unfinished shard), instead of a warning.
    #[arg(long)]
    complete: bool,
}

pub fn run(a: Args) -> CliResult {
    match a.command {
        Some(Command::Merge(m)) => merge(m),
        Some(Command::Report(r)) => report(&r.dir),
        None => run_sweep(a.run),
    }
}

fn run_sweep(a: RunArgs) -> CliResult {
    let (Some(path), Some(out)) = (a.sweep, a.out) else {
        unreachable!("clap requires the sweep file and --out")
    };
    let sweep = Sweep::load(&path)?;
    for note in &sweep.notes {
        eprintln!("note: {note}");
    }
    let shard = a.shard.unwrap_or(Shard::ALL);
    let bar = Progress::new(
        0,
        "{bar:40} {pos}/{len} rows, {per_sec}, ETA {eta} {msg}",
        "rows",
    );
    let started = std::cell::Cell::new(false);
    let summary = sweep::run(&sweep, &out, shard, &|p| {
        if !started.replace(true) {
            // Rows done by an earlier run do not count towards the rate.
            bar.bar().set_length(p.total as u64);
            bar.bar().set_position(p.done as u64);
            bar.bar().reset_eta();
        }
        bar.set(p.done as u64, Some(p.total as u64), p.message);
    })?;
    bar.finish();
    if summary.dropped > 0 {
        eprintln!(
            "warning: {} rows of {} were redone: repeated with different figures, in no plan \
             of this sweep, or failed by the system (results.jsonl)",
            summary.dropped,
            out.display()
        );
    }
    let total = summary.seconds.max(1e-9);
    outln!(
        "sweep {} (shard {shard}): {} rows in {} ({} computed now, {} already there, {} failed) \
         in {:.1} s",
        path.display(),
        summary.rows,
        out.display(),
        summary.computed,
        summary.skipped,
        summary.failed,
        summary.seconds
    )?;
    outln!(
        "time: renders {:.1} s ({} new), noise {:.1} s, reconstructions {:.1} s, \
         per-row overhead {:.2} s ({:.1}% of the run)",
        summary.render_seconds,
        summary.renders,
        summary.noise_seconds,
        summary.reconstruct_seconds,
        summary.overhead_seconds,
        100.0 * summary.overhead_seconds / total
    )?;
    // A shard holds part of the rows: its report comes with the merge.
    if shard == Shard::ALL {
        report(&out)?;
    }
    Ok(())
}

fn report(dir: &Path) -> CliResult {
    let written = report::write(dir)?;
    outln!(
        "report: {} rows ({} with figures), {} cells, {} plots, {} picture grids → {}",
        written.rows,
        written.rows_with_figures,
        written.cells,
        written.plots.len(),
        written.grids.len(),
        dir.join("index.html").display()
    )?;
    for missing in &written.missing_pictures {
        eprintln!("warning: picture not found: {missing}");
    }
    Ok(())
}

fn merge(a: MergeArgs) -> CliResult {
    let merged = sweep::merge(&a.dirs, &a.out, a.complete)?;
    outln!(
        "merged {} folders into {}: {} rows",
        a.dirs.len(),
        a.out.display(),
        merged.rows
    )?;
    if merged.missing > 0 {
        eprintln!(
            "warning: {} rows of the sweep are in none of the folders (shards not run or not finished)",
            merged.missing
        );
    }
    report(&a.out)
}
