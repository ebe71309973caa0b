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
mod export;
mod import;
mod inspect;
mod reconstruct;
mod render;

use clap::{Parser, Subcommand};
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
    /// Render a dataset preset (builtin, a, b or a TOML file) into view folders and dataset.json.
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

/// Errors end the program with a message and a non-zero exit code, never a panic.
type CliResult = Result<(), Box<dyn std::error::Error>>;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
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
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output has gone; it asked for no more.
        Err(e) if is_broken_pipe(e.as_ref()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(exit_code(e.as_ref()))
        }
    }
}

/// Exit codes (README): 0 done; 1 the system failed us (a read or write
/// the operating system refused); 2 the command line or an input is wrong
/// (clap's own usage errors also exit with 2). Scripts and job schedulers
/// can retry the first and must not retry the second.
fn exit_code(e: &(dyn std::error::Error + 'static)) -> u8 {
    match e.downcast_ref::<sfp_core::Error>() {
        Some(sfp_core::Error::Io { .. }) => 1,
        _ => 2,
    }
}

fn is_broken_pipe(e: &(dyn std::error::Error + 'static)) -> bool {
    e.downcast_ref::<std::io::Error>()
        .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
}

/// `--size` of every subcommand: `N` for N × N, or `WIDTHxHEIGHT`.
fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let parse = |v: &str| {
        v.trim().parse::<usize>().map_err(|_| {
            format!("{v:?} is not a whole number (expected N or WIDTHxHEIGHT like 512x512)")
        })
    };
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((parse(w)?, parse(h)?)),
        None => parse(s).map(|n| (n, n)),
    }
}

/// `--size` of the subcommands whose views are square (analytic shapes,
/// dataset presets, the demo): `N`, or `NxN`.
fn parse_square_size(s: &str) -> Result<usize, String> {
    match parse_size(s)? {
        (w, h) if w == h => Ok(w),
        (w, h) => Err(format!("{w}x{h}: these views are square, give N or NxN")),
    }
}

/// Parses `x,y,z` into a vector.
fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers like 0.3,0.2,1, got {s:?}"
        ));
    }
    let mut v = [0.0f64; 3];
    for (vi, p) in v.iter_mut().zip(parts) {
        *vi = p.parse().map_err(|_| format!("{p:?} is not a number"))?;
        if !vi.is_finite() {
            return Err(format!("{p:?} is not a finite number"));
        }
    }
    Ok(v)
}
