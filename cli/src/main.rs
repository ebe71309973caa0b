//! `sfp`: the polar-sfp command-line tool. Argument parsing, progress and
//! printing only; the work is done by the library crates.

/// `print!` for what a command reports on stdout, returning the write's
/// error: a reader that stops early (`sfp inspect VIEW | head`) then ends
/// the program quietly instead of a panic in `print!`.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*)
    }};
}

/// `println!` in the manner of [`out!`].
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}

mod analytic;
mod bench;
mod dataset;
mod demo;
mod eval;
mod exit;
mod export;
mod import;
mod inspect;
mod progress;
mod reconstruct;
mod render;
mod values;

use clap::{Parser, Subcommand};
use exit::CliResult;
use sfp_reconstruct::solver::memory;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "sfp",
    version,
    about = "Shape from polarization: render, reconstruct, evaluate"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write an exact, noise-free view of an analytic shape (the test oracle).
    Analytic(analytic::Args),
    /// Print a view's size and DoP/AoP statistics and write its preview pictures.
    Inspect(inspect::Args),
    /// The main job: default scenes → views → reconstructions → metrics.
    Demo(demo::Args),
    /// Render a scene file into a view folder with the polarization path tracer.
    Render(render::Args),
    /// Render a dataset preset (builtin, a, b, glossy or a TOML file) into view folders and dataset.json.
    Dataset(dataset::Args),
    /// Turn a real capture (polarization-sensor raw frame or four polarizer images) into a view.
    Import(import::Args),
    /// Reconstruct normals and height from a view's polarizer images (`--help` lists every method's options).
    Reconstruct(reconstruct::Args),
    /// Score a reconstruction's normals.exr against a view's ground truth.
    Eval(eval::Args),
    /// Write a reconstruction as .npy/16-bit PNG, or a view as the per-angle folder layout.
    Export(export::Args),
    /// Run a sweep file (views × axes × methods × noise seeds) into results.jsonl/csv; `merge` joins shards.
    Bench(bench::Args),
}

/// Under an address-space limit, a pool with no more threads (and malloc
/// arenas) than fit it (`memory::fit_to_address_space`), for the command to
/// run in: each solving thread reserves workspaces no caller can ask for
/// fallibly (600 MiB of dense-kernel workspace on a 300 MiB L3 cache), so a
/// thread too many under `ulimit -v` aborts. The main thread only waits, so
/// it reserves none. Without a limit, `None`: rayon's default pool.
fn pool_fitting_the_address_space() -> Option<rayon::ThreadPool> {
    memory::address_space_left()?;
    let threads = memory::fit_to_address_space(memory::default_threads());
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .ok()
}

fn main() -> ExitCode {
    // Before anything the build's instructions could run in.
    if let Some(refusal) = sfp_core::instruction_set::refusal() {
        eprintln!("error: {refusal}");
        return ExitCode::from(2);
    }
    let cli = Cli::parse();
    match pool_fitting_the_address_space() {
        Some(pool) => pool.install(|| exit::code(run(cli.command))),
        None => exit::code(run(cli.command)),
    }
}

fn run(command: Command) -> CliResult {
    match command {
        Command::Analytic(a) => analytic::run(a),
        Command::Inspect(a) => inspect::run(a),
        Command::Eval(a) => eval::run(a),
        Command::Export(a) => export::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Render(a) => render::run(a),
        Command::Dataset(a) => dataset::run(a),
        Command::Import(a) => import::run(a),
        Command::Reconstruct(a) => reconstruct::run(a),
        Command::Bench(a) => bench::run(a),
    }
}
