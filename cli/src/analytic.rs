//! `sfp analytic`.

use crate::exit::CliResult;
use crate::values::parse_vec3;
use sfp_core::analytic::{AnalyticScene, Shape};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Shape to render.
    #[arg(long, value_enum, default_value = "sphere")]
    shape: ShapeArg,
    /// Image width and height in pixels: N, or NxN.
    #[arg(long, default_value = "256", value_parser = crate::values::parse_square_size, allow_negative_numbers = true)]
    size: usize,
    /// Refractive index.
    #[arg(long, default_value_t = 1.5, allow_negative_numbers = true)]
    eta: f64,
    /// Albedo.
    #[arg(long, default_value_t = 0.8, allow_negative_numbers = true)]
    albedo: f64,
    /// Direction towards the light in the camera frame (x right, y up, z to the camera).
    #[arg(long, default_value = "0.3,0.2,1", value_parser = parse_vec3, allow_hyphen_values = true)]
    light: [f64; 3],
    /// Output view folder.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ShapeArg {
    Sphere,
    Blobs,
}

pub fn run(a: Args) -> CliResult {
    let scene = AnalyticScene {
        shape: match a.shape {
            ShapeArg::Sphere => Shape::Sphere,
            ShapeArg::Blobs => Shape::Blobs,
        },
        size: a.size,
        eta: a.eta,
        albedo: a.albedo,
        light: a.light,
    };
    scene.render()?.write(&a.out)?;
    outln!("wrote {}", a.out.display())?;
    Ok(())
}
