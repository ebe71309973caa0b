//! `sfp render`.

use crate::exit::CliResult;
use crate::progress::Progress;
use sfp_renderer::render::{RenderOptions, render_with_progress};
use sfp_renderer::scene::Scene;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (TOML, see scenes/README.md).
    scene: PathBuf,
    /// Output view folder.
    #[arg(long)]
    out: PathBuf,
    /// Samples per pixel (overrides [render] spp).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::values::parse_whole::<u32>)]
    spp: Option<u32>,
    /// Random seed (overrides [render] seed).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::values::parse_whole::<u64>)]
    seed: Option<u64>,
    /// Image size WIDTHxHEIGHT, or N for N×N (overrides [camera] width and height).
    #[arg(long, value_parser = crate::values::parse_size)]
    size: Option<(usize, usize)>,
}

pub fn run(a: Args) -> CliResult {
    let mut scene = Scene::load(&a.scene)?;
    scene.override_settings(a.spp, a.seed, a.size)?;
    let bar = Progress::new(
        scene.desc.camera.height as u64,
        "rendering {bar:40} {pos}/{len} rows [{elapsed} < {eta}]",
        "image rows",
    );
    let rendered = render_with_progress(&scene, &RenderOptions::default(), &|_, _| bar.inc(None))?;
    bar.finish();
    rendered.write(&a.out)?;
    let s = rendered.stats;
    outln!(
        "wrote {} in {:.2} s: {} samples ({:.2} M samples/s), {:.2} M rays/s, {} triangles",
        a.out.display(),
        s.seconds,
        s.samples,
        s.samples as f64 / s.seconds / 1e6,
        s.rays as f64 / s.seconds / 1e6,
        s.triangles
    )?;
    Ok(())
}
