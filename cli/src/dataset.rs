//! `sfp dataset`.

use crate::exit::CliResult;
use crate::progress::Progress;
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
    let plan = dataset.plan()?;
    let todo = plan
        .iter()
        .filter(|v| !v.is_rendered_in(&a.out.join(&v.folder)))
        .count();
    let bar = Progress::new(
        todo as u64,
        "rendering {bar:40} {pos}/{len} views {msg} [{elapsed} < {eta}]",
        "views rendered",
    );
    let generated = dataset.generate(&plan, &a.out, &|view, skipped| {
        if !skipped {
            bar.inc(Some(&view.folder));
        }
    })?;
    bar.finish();
    let replaced = match generated.replaced {
        0 => String::new(),
        n => format!(", {n} of them replacing views rendered with other settings"),
    };
    outln!(
        "dataset {:?}: {} views in {} ({} rendered{replaced}, {} already complete) in {:.1} s",
        dataset.desc.dataset.name,
        plan.len(),
        a.out.display(),
        generated.rendered,
        generated.skipped,
        generated.seconds
    )?;
    Ok(())
}
