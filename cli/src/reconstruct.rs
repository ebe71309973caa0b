//! `sfp reconstruct`.

use crate::{CliResult, parse_vec3};
use indicatif::{ProgressBar, ProgressStyle};
use sfp_core::view::View;
use sfp_reconstruct::atkinson::{Atkinson, AtkinsonParams};
use sfp_reconstruct::mahmoud::{Mahmoud, MahmoudLight};
use sfp_reconstruct::output::write_result;
use sfp_reconstruct::smith::{LightSource, Smith};
use sfp_reconstruct::{Input, Method};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct Args {
    /// View folder (reads input/; gt/ only to write metrics.json).
    view: PathBuf,
    /// Reconstruction method.
    #[arg(long, value_enum, default_value = "smith")]
    method: MethodArg,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Refractive index assumed by the method.
    #[arg(long, default_value_t = 1.5)]
    eta: f64,
    /// Known direction towards the light (camera frame); estimated when absent.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    light: Option<[f64; 3]>,
    /// Estimate ambient + directional (first-order spherical-harmonic) lighting.
    #[arg(long, conflicts_with = "light")]
    ambient: bool,
    /// Laplacian smoothness weight (Smith).
    #[arg(long, default_value_t = 0.1)]
    lambda: f64,
    /// Seed of the light estimator's starting lights.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum MethodArg {
    Smith,
    Atkinson,
    Mahmoud,
}

fn method(a: &Args) -> Result<Box<dyn Method>, String> {
    if !(a.eta > 1.0 && a.eta.is_finite()) {
        return Err(format!("--eta {} must be a finite number > 1", a.eta));
    }
    Ok(match a.method {
        MethodArg::Smith => {
            if !(a.lambda >= 0.0 && a.lambda.is_finite()) {
                return Err(format!("--lambda {} must be finite and ≥ 0", a.lambda));
            }
            Box::new(Smith {
                eta: a.eta,
                lambda: a.lambda,
                light: match (a.light, a.ambient) {
                    (Some(d), _) => LightSource::Direction(d),
                    (None, true) => LightSource::EstimateAmbient,
                    (None, false) => LightSource::Estimate,
                },
                seed: a.seed,
                ..Smith::default()
            })
        }
        MethodArg::Atkinson => Box::new(Atkinson {
            params: AtkinsonParams {
                eta: a.eta,
                ..AtkinsonParams::default()
            },
        }),
        MethodArg::Mahmoud => Box::new(Mahmoud {
            eta: a.eta,
            light: match (a.light, a.ambient) {
                (Some(d), _) => MahmoudLight::Direction(d),
                (None, true) => MahmoudLight::EstimateAmbient,
                (None, false) => MahmoudLight::Estimate,
            },
            seed: a.seed,
        }),
    })
}

pub fn run(a: Args) -> CliResult {
    let method = method(&a)?;
    let view = View::read(&a.view)?;
    let input = Input::from_view(&view.input).map_err(|e| format!("{}: {e}", a.view.display()))?;
    // A spinner with the elapsed time: large captures take a minute.
    let spinner = ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("valid progress template"),
    );
    spinner.set_message(format!("{}: {} pixels", method.name(), input.mask.count()));
    spinner.enable_steady_tick(Duration::from_millis(120));
    let start = Instant::now();
    let rec = method.reconstruct(&input);
    spinner.finish_and_clear();
    let rec = rec?;
    let seconds = start.elapsed().as_secs_f64();
    let gt_mask = view.gt.as_ref().map(|gt| {
        view.input
            .mask
            .clone()
            .unwrap_or_else(|| gt.normals.map(|n| *n != [0.0; 3]))
    });
    let gt = view.gt.as_ref().zip(gt_mask.as_ref());
    let metrics = write_result(&a.out, &rec, &input.mask, gt)?;
    println!(
        "{} reconstructed {} pixels in {seconds:.2} s → {}",
        method.name(),
        input.mask.count(),
        a.out.display()
    );
    if let Some(m) = metrics {
        println!("{}", serde_json::to_string_pretty(&m)?);
    }
    Ok(())
}
