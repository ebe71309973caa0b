//! A small sweep folder made from exact analytic views, in the layout the
//! sweep engine writes (`results.jsonl`, `timings.csv`, `sweep.toml`,
//! `provenance.json`, noise-free views and kept result folders): for the
//! report's tests and its example, and to look at a report without running
//! a real sweep.
//!
//! Axes: `eta` (the true refractive index of the rendered view) and
//! `noise_read_sigma` (electrons); every seed re-exposes the noise-free
//! Stokes with shot and read noise through the renderer's sensor.

use crate::sweep::row::{AxisValue, Row};
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::view::{View, ViewInput};
use sfp_core::{Error, Result, io};
use sfp_reconstruct::registry::{self, MethodConfig};
use sfp_renderer::scene::SensorDesc;
use sfp_renderer::sensor;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct Synthetic {
    /// Image side, pixels.
    pub size: usize,
    pub shapes: Vec<Shape>,
    pub etas: Vec<f64>,
    pub read_noise: Vec<f64>,
    pub seeds: Vec<u64>,
    /// Method labels and configurations.
    pub methods: Vec<(String, MethodConfig)>,
    /// Keep result folders (picture grids) of the rows with this seed.
    pub pictures_seed: Option<u64>,
}

impl Synthetic {
    /// A quick sweep: one sphere and one blob view at 48², two η, two
    /// seeds, Smith, SMSfP and SMSfP without PARG.
    pub fn small() -> Synthetic {
        let mut no_parg = serde_json::Map::new();
        no_parg.insert("parg".into(), false.into());
        Synthetic {
            size: 48,
            shapes: vec![Shape::Sphere, Shape::Blobs],
            etas: vec![1.3, 1.6],
            read_noise: vec![2.0],
            seeds: vec![0, 1],
            methods: vec![
                (
                    "smith".into(),
                    MethodConfig::default_for("smith").expect("registered"),
                ),
                (
                    "smsfp".into(),
                    MethodConfig::default_for("smsfp").expect("registered"),
                ),
                (
                    "smsfp-no-parg".into(),
                    MethodConfig::with_options("smsfp", no_parg).expect("registered"),
                ),
            ],
            pictures_seed: Some(0),
        }
    }
}

fn shape_name(shape: Shape) -> &'static str {
    match shape {
        Shape::Sphere => "sphere",
        Shape::Blobs => "blobs",
    }
}

/// Writes the sweep folder `dir` and returns its rows.
pub fn write(dir: &Path, s: &Synthetic) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    let mut timings =
        String::from("key,method,pixels,noise_seconds,reconstruct_seconds,overhead_seconds\n");
    for &shape in &s.shapes {
        for &eta in &s.etas {
            let scene = AnalyticScene {
                shape,
                size: s.size,
                eta,
                light: [0.3, 0.2, 1.0],
                ..AnalyticScene::default()
            };
            let view = scene.render()?;
            let name = shape_name(shape);
            let view_rel = format!("views/{name}-eta{eta}");
            view.write(&dir.join(&view_rel))?;
            let stokes = view
                .gt
                .as_ref()
                .and_then(|gt| gt.stokes.as_ref())
                .expect("analytic views have noise-free Stokes");
            let mask = view.input.mask.clone().expect("analytic views have a mask");
            for &read_noise in &s.read_noise {
                for &seed in &s.seeds {
                    let start = Instant::now();
                    let desc = SensorDesc {
                        read_noise,
                        ..SensorDesc::default()
                    };
                    let exposed = sensor::expose(&desc, stokes, &mask, seed, 0);
                    let noisy = View {
                        input: ViewInput {
                            pol: exposed.pol,
                            bits: desc.bits,
                            mask: Some(mask.clone()),
                        },
                        gt: view.gt.clone(),
                        meta: view.meta.clone(),
                        problems: Vec::new(),
                        source: None,
                    };
                    let noise_seconds = start.elapsed().as_secs_f64();
                    let axes: BTreeMap<String, AxisValue> = [
                        ("eta".to_string(), AxisValue::Number(eta)),
                        (
                            "noise_read_sigma".to_string(),
                            AxisValue::Number(read_noise),
                        ),
                    ]
                    .into();
                    for (label, config) in &s.methods {
                        let start = Instant::now();
                        let rel =
                            format!("results/{name}-eta{eta}-read{read_noise}-s{seed}/{label}");
                        let out = dir.join(&rel);
                        let outcome = registry::run(&noisy, config, &out);
                        let keep = s.pictures_seed == Some(seed);
                        let key = format!("{name}|eta={eta}|read={read_noise}|{label}|{seed}");
                        let (metrics, error, seconds, pixels) = match outcome {
                            Ok(o) => (o.metrics, None, o.seconds, o.pixels),
                            Err(e) => (None, Some(e.to_string()), 0.0, mask.count()),
                        };
                        if !keep && out.is_dir() {
                            std::fs::remove_dir_all(&out).map_err(|e| Error::io(&out, e))?;
                        }
                        let overhead = (start.elapsed().as_secs_f64() - seconds).max(0.0);
                        let _ = writeln!(
                            timings,
                            "{key},{label},{pixels},{noise_seconds},{seconds},{overhead}"
                        );
                        rows.push(Row {
                            key,
                            dataset: "analytic".into(),
                            view: format!("{name}-eta{eta}"),
                            object: name.into(),
                            axes: axes.clone(),
                            method: label.clone(),
                            config: config.to_value(),
                            seed,
                            metrics,
                            error,
                            view_dir: view_rel.clone(),
                            pictures: keep.then_some(rel),
                        });
                    }
                }
            }
        }
    }
    let mut jsonl = String::new();
    for r in &rows {
        jsonl.push_str(&serde_json::to_string(r).expect("rows serialise"));
        jsonl.push('\n');
    }
    io::write_atomic(&dir.join("results.jsonl"), jsonl.as_bytes())?;
    io::write_atomic(&dir.join("timings.csv"), timings.as_bytes())?;
    let mut toml = String::from("# A synthetic sweep of exact analytic views.\n");
    let _ = writeln!(toml, "size = {}", s.size);
    let _ = writeln!(
        toml,
        "shapes = [{}]",
        s.shapes
            .iter()
            .map(|&sh| format!("\"{}\"", shape_name(sh)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(toml, "seeds = {:?}", s.seeds);
    let _ = writeln!(
        toml,
        "\n[axes]\neta = {:?}\nnoise_read_sigma = {:?}",
        s.etas, s.read_noise
    );
    for (label, config) in &s.methods {
        let _ = writeln!(
            toml,
            "\n[methods.\"{label}\"]\nconfig = '{}'",
            config.to_value()
        );
    }
    io::write_atomic(&dir.join("sweep.toml"), toml.as_bytes())?;
    let provenance = serde_json::json!({
        "version": sfp_core::SOFTWARE_VERSION,
        "commit": "unknown (synthetic sweep)",
        "crates": { "sfp-benchmarks": env!("CARGO_PKG_VERSION") },
        "cpu": cpu_name(),
        "threads": std::thread::available_parallelism().map_or(1, |n| n.get()),
        "started": "synthetic",
    });
    io::write_atomic(
        &dir.join("provenance.json"),
        &serde_json::to_vec_pretty(&provenance).expect("provenance serialises"),
    )?;
    Ok(rows)
}

/// The CPU's model name from `/proc/cpuinfo`, or `unknown`.
fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}
