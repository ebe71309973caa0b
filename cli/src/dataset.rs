//! `sfp dataset`.

use crate::exit::CliResult;
use crate::progress::Progress;
use sfp_benchmarks::sweep::shard::Shard;
use sfp_renderer::dataset::Dataset;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Preset name (builtin, a, b, glossy) or a preset file (TOML, see scenes/README.md).
    preset: String,
    /// Output dataset folder.
    #[arg(long)]
    out: PathBuf,
    /// Views per object (overrides [dataset] views_per_object).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::values::parse_whole::<usize>)]
    views: Option<usize>,
    /// Image width and height: N, or NxN (overrides [camera] width and height).
    #[arg(long, value_parser = crate::values::parse_square_size, allow_negative_numbers = true)]
    size: Option<usize>,
    /// Samples per pixel (overrides [render] spp).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::values::parse_whole::<u32>)]
    spp: Option<u32>,
    /// Random seed of the renders and the orientations (overrides [render] seed).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::values::parse_whole::<u64>)]
    seed: Option<u64>,
    /// Use each object's albedo texture (sets [dataset] textured = true): of
    /// the presets, only a's duck (its GLB texture) and b's mug (mug.png)
    /// have one; the other objects are unchanged.
    #[arg(long)]
    textured: bool,
    /// Give objects their spatially varying material (sets [dataset] svbrdf =
    /// true): every preset object has one (albedo, specular, roughness and
    /// normal maps, per object in scenes/README.md) but glossy's, which draw
    /// their material per view; objects of a preset file without an
    /// [object.svbrdf] table are unchanged.
    #[arg(long)]
    svbrdf: bool,
    /// Write the views straight into a training layout instead of view
    /// folders: `sfpuel`, the per-angle layout `sfp export VIEW` writes
    /// (pol000/ pol045/ pol090/ pol135/ mask/ normal/ and layout.json),
    /// resumed where a view's normal/NAME.npy exists.
    #[arg(long, value_parser = ["sfpuel"])]
    layout: Option<String>,
    /// Render only shard K of N (1 ≤ K ≤ N) of the views, dealt round-robin;
    /// shards writing a layout may share one --out.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
}

pub fn run(a: Args) -> CliResult {
    // A bare name is a preset (an unknown one lists the known ones), a path a file.
    let path = Path::new(&a.preset);
    let mut dataset = if path.extension().is_some() {
        Dataset::load(path)?
    } else {
        Dataset::preset(&a.preset)?
    };
    dataset.override_settings(a.views, a.size, a.spp, a.seed)?;
    if a.textured {
        dataset.desc.dataset.textured = true;
    }
    if a.svbrdf {
        dataset.desc.dataset.svbrdf = true;
    }
    let shard = a.shard.unwrap_or(Shard::ALL);
    let plan: Vec<_> = dataset
        .plan()?
        .into_iter()
        .enumerate()
        .filter(|(i, _)| shard.owns(*i))
        .map(|(_, v)| v)
        .collect();
    let todo = plan
        .iter()
        .filter(|v| match a.layout {
            Some(_) => !v.is_in_layout(&a.out),
            None => !v.is_rendered_in(&a.out.join(&v.folder)),
        })
        .count();
    let bar = Progress::new(
        todo as u64,
        "rendering {bar:40} {pos}/{len} views {msg} [{elapsed} < {eta}]",
        "views rendered",
    );
    let progress = |view: &sfp_renderer::dataset::PlannedView, skipped: bool| {
        if !skipped {
            bar.inc(Some(&view.folder));
        }
    };
    let generated = match a.layout {
        Some(_) => dataset.generate_layout(&plan, &a.out, &progress)?,
        None => dataset.generate(&plan, &a.out, &progress)?,
    };
    bar.finish();
    let replaced = match generated.replaced {
        0 => String::new(),
        n => format!(", {n} of them replacing views rendered with other settings"),
    };
    let shard = match a.shard {
        Some(s) => format!(" (shard {s})"),
        None => String::new(),
    };
    let per_minute = generated.rendered as f64 * 60.0 / generated.seconds.max(1e-9);
    outln!(
        "dataset {:?}{shard}: {} views in {} ({} rendered{replaced}, {} already complete) in {:.1} s, {per_minute:.1} views a minute",
        dataset.desc.dataset.name,
        plan.len(),
        a.out.display(),
        generated.rendered,
        generated.skipped,
        generated.seconds
    )?;
    Ok(())
}
