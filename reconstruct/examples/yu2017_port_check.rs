//! The port check of `yu2017` (docs/yu2017.md, "Port check"): reads one
//! case written by the authors' synthetic demo run under GNU Octave (their
//! polarizer images, mask, specular mask, and their ratio-stage and
//! full-stage heights at every 2nd pixel), runs the port on the same images
//! at the same settings, and prints the mean angular difference between
//! the two methods' normals (both through the port's stencils on the
//! refined mask) and the port's time.
//!
//! `cargo run --release -p sfp-reconstruct --example yu2017_port_check -- CASE_DIR [albedo] [quirks] [finest=STEP]`
//!
//! `CASE_DIR` holds raw little-endian `f64` arrays in column-major order:
//! `images.f64` (H×W×7, polarizer at 0°, 30°, …, 180°), `mask.f64`,
//! `spec.f64` (H×W, 0/1), `stage_a.f64`, `stage_b.f64` (H/2×W/2, NaN
//! outside). `albedo` selects their varying-albedo case (the known light
//! 15° towards +x; otherwise the light is estimated); `quirks` sets the
//! `authors_quirks` option.

use sfp_core::{Image, Mask};
use sfp_reconstruct::light::LightSource;
use sfp_reconstruct::methods::Yu2017;
use sfp_reconstruct::methods::yu2017::{Observations, pyramid};
use sfp_reconstruct::solver::lsq::Solver;
use sfp_reconstruct::solver::ordering::Ordering;
use std::path::Path;
use std::time::Instant;

fn read(path: &Path) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect())
}

/// Plane `i` of a column-major `size × size × planes` array as an image.
fn plane(v: &[f64], size: usize, i: usize) -> Image<f64> {
    Image::from_fn(size, size, |x, y| v[i * size * size + x * size + y])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(Path::new) else {
        return Err("usage: yu2017_port_check CASE_DIR [albedo] [quirks] [finest=STEP]".into());
    };
    let albedo = args.iter().any(|a| a == "albedo");
    // `finest=STEP` stops the ratio stage at that step and compares with
    // `stage_a_STEP.f64` (the authors' pyramid stopped there).
    let finest = args
        .iter()
        .find_map(|a| a.strip_prefix("finest="))
        .map_or(Ok(2), str::parse::<usize>)?;
    let mask = read(&dir.join("mask.f64"))?;
    let size = (mask.len() as f64).sqrt() as usize;
    let images = read(&dir.join("images.f64"))?;
    let count = images.len() / (size * size);
    let to_mask = |v: &[f64]| Mask::from_fn(size, size, |x, y| v[x * size + y] != 0.0);
    let obs = Observations {
        angles: (0..count).map(|j| (30.0 * j as f64).to_radians()).collect(),
        images: (0..count).map(|j| plane(&images, size, j)).collect(),
        mask: to_mask(&mask),
        specular: to_mask(&read(&dir.join("spec.f64"))?),
    };
    let mut method = Yu2017 {
        authors_quirks: args.iter().any(|a| a == "quirks"),
        ..Yu2017::default()
    };
    if albedo {
        let s = 15f64.to_radians();
        method.shared.light = LightSource::Direction([s.sin(), 0.0, s.cos()]);
    }
    let start = Instant::now();
    let mut solver = Solver::new(Ordering::default());
    let mut settings = method.settings(finest);
    if finest != 2 {
        settings.full = None;
    }
    let out = pyramid::run(&obs, &settings, &mut solver)?;
    let seconds = start.elapsed().as_secs_f64();
    let grid = size.div_ceil(finest);
    let stages = if finest == 2 {
        vec![
            ("ratio", &out.ratio[..], "stage_a.f64".to_string()),
            ("full", out.heights(), "stage_b.f64".into()),
        ]
    } else {
        vec![("ratio", &out.ratio[..], format!("stage_a_{finest}.f64"))]
    };
    for (stage, ours, file) in stages {
        let theirs = plane(&read(&dir.join(&file))?, grid, 0);
        let theirs = out.level.domain.gather(&theirs);
        if theirs.iter().any(|v| v.is_nan()) {
            return Err(format!("{file}: NaN inside the port's refined mask").into());
        }
        let a = pyramid::normals(&out.level, ours);
        let b = pyramid::normals(&out.level, &theirs);
        let errors: Vec<f64> = (0..out.level.domain.len())
            .map(|k| {
                let (x, y) = out.level.domain.pixel(k);
                let (u, v) = (a.get(x, y), b.get(x, y));
                let dot: f32 = (0..3).map(|i| u[i] * v[i]).sum();
                f64::from(dot.clamp(-1.0, 1.0)).acos().to_degrees()
            })
            .collect();
        let mut sorted = errors.clone();
        sorted.sort_by(f64::total_cmp);
        println!(
            "{stage} stage: {} px, mean angular difference {:.3}°, median {:.3}°, 95th pct {:.3}°",
            errors.len(),
            errors.iter().sum::<f64>() / errors.len() as f64,
            sorted[sorted.len() / 2],
            sorted[sorted.len() * 95 / 100],
        );
    }
    for l in &out.levels {
        let runs: Vec<String> = l
            .runs
            .iter()
            .map(|r| format!("{}:{:?}:{:.4}", r.iterations, r.exit, r.cost))
            .collect();
        println!(
            "step {:>2}: n {:>5}, prior {:>5}, runs {}",
            l.step,
            l.unknowns,
            l.prior_pixels,
            runs.join(" ")
        );
    }
    let runs: Vec<String> = out
        .full_runs
        .iter()
        .map(|r| format!("{}:{:?}:{:.4e}", r.iterations, r.exit, r.cost))
        .collect();
    println!("full: runs {}", runs.join(" "));
    println!(
        "port: {seconds:.2} s (ratio stage {:.2} s, full stage {:.2} s)",
        out.seconds_ratio, out.seconds_full
    );
    Ok(())
}
