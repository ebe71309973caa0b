//! Writes the report of a sweep folder, making a synthetic sweep of exact
//! analytic views there first when it holds no `results.jsonl`:
//!
//!     cargo run --release -p sfp-benchmarks --example sweep_report -- DIR [--all]
//!
//! `--all` sweeps every registered method (and SMSfP without PARG) instead
//! of the quick set.

use sfp_benchmarks::report::{self, synthetic};
use sfp_reconstruct::registry::{METHODS, MethodConfig};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .map(PathBuf::from)
    else {
        eprintln!("usage: sweep_report DIR [--all]");
        std::process::exit(2);
    };
    if !dir.join("results.jsonl").is_file() {
        let mut s = synthetic::Synthetic::small();
        if args.iter().any(|a| a == "--all") {
            let ablation = s.methods.pop().expect("the quick set has an ablation");
            s.methods = METHODS
                .iter()
                .map(|m| {
                    (
                        m.to_string(),
                        MethodConfig::default_for(m).expect("registered"),
                    )
                })
                .collect();
            s.methods.push(ablation);
            s.read_noise = vec![2.0, 20.0];
        }
        let start = Instant::now();
        let rows = synthetic::write(&dir, &s)?;
        println!(
            "synthetic sweep: {} rows in {:.1} s",
            rows.len(),
            start.elapsed().as_secs_f64()
        );
    }
    let start = Instant::now();
    let written = report::write(&dir)?;
    println!(
        "report: {} rows, {} cells, {} plots, {} grids in {:.2} s → {}",
        written.rows,
        written.cells,
        written.plots.len(),
        written.grids.len(),
        start.elapsed().as_secs_f64(),
        dir.join("index.html").display()
    );
    for m in &written.missing_pictures {
        println!("missing picture: {m}");
    }
    Ok(())
}
