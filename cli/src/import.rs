//! `sfp import`: a real capture (a division-of-focal-plane raw frame, or four
//! polarizer images) as a view folder.

use crate::CliResult;
use serde_json::json;
use sfp_core::capture::{self, CaptureSummary, MaskSource};
use sfp_core::export;
use sfp_core::io;
use sfp_core::mosaic::{Demosaic, Pattern, demosaic};
use sfp_core::view::{Meta, View};
use std::path::{Path, PathBuf};

#[derive(clap::ValueEnum, Clone, Copy)]
enum Method {
    /// One pixel per 2×2 cell (half resolution, no interpolation).
    Superpixel,
    /// Full resolution, each missing value the mean of its nearest photosites.
    Bilinear,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["mosaic", "angles", "layout"])))]
pub struct Args {
    /// Raw frame of a division-of-focal-plane polarization sensor (8/16-bit PNG).
    #[arg(long, value_name = "RAW.png")]
    mosaic: Option<PathBuf>,
    /// Polarizer angles of a 2×2 mosaic cell in reading order.
    #[arg(long, default_value = "90,45,135,0", requires = "mosaic")]
    pattern: String,
    /// How the mosaic is demosaiced.
    #[arg(long, value_enum, default_value = "superpixel", requires = "mosaic")]
    demosaic: Method,
    /// Four images behind polarizers at 0°, 45°, 90° and 135°, in that order.
    #[arg(long, num_args = 4, value_names = ["P0", "P45", "P90", "P135"])]
    angles: Option<Vec<PathBuf>>,
    /// A per-angle layout folder (pol000/ pol045/ pol090/ pol135/, optional
    /// mask/ and normal/, as `sfp export` writes it): imports one view with
    /// its mask and ground-truth normals.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["mask", "window", "sensor_bits"])]
    layout: Option<PathBuf>,
    /// Which view of the layout (its file name without .png); needed when it holds several.
    #[arg(long, requires = "layout")]
    name: Option<String>,
    /// Object mask image (non-zero = object), same size as the polarizer images.
    #[arg(long, conflicts_with = "window")]
    mask: Option<PathBuf>,
    /// Object = pixels whose mean polarizer code lies in LOW,HIGH (fractions of full scale).
    #[arg(long, value_name = "LOW,HIGH", value_delimiter = ',')]
    window: Option<Vec<f64>>,
    /// Sensor bit depth when below the file's (e.g. 12 for 12-bit data in
    /// 16-bit PNGs): sets the saturation code.
    #[arg(long, value_name = "BITS", allow_negative_numbers = true)]
    sensor_bits: Option<u8>,
    /// Output view folder.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: Args) -> CliResult {
    let mut meta = Meta::new("sfp import");
    if let Some(dir) = &a.layout {
        let mut view = export::read_layout(dir, a.name.as_deref())?;
        meta.extra.insert(
            "capture".into(),
            json!({ "layout": dir.display().to_string(), "name": a.name }),
        );
        view.meta = Some(meta);
        view.write(&a.out)?;
        return print_summary(&a.out, &view, None);
    }
    let (pol, bits) = match (&a.mosaic, &a.angles) {
        (Some(raw), _) => {
            let pattern = Pattern::parse(&a.pattern)?;
            let method = match a.demosaic {
                Method::Superpixel => Demosaic::SuperPixel,
                Method::Bilinear => Demosaic::Bilinear,
            };
            let frame = io::read_mono_png(raw)?;
            let bits = frame.bits();
            let pol = demosaic(&frame.into_u16(), pattern, method)
                .map_err(|e| format!("{}: {e}", raw.display()))?;
            meta.extra.insert(
                "capture".into(),
                json!({
                    "mosaic": raw.display().to_string(),
                    "pattern": pattern.to_string(),
                    "demosaic": format!("{method:?}"),
                }),
            );
            (pol, bits)
        }
        (None, Some(paths)) => {
            let paths: [&std::path::Path; 4] = std::array::from_fn(|i| paths[i].as_path());
            let (pol, bits) = capture::read_four(&paths)?;
            meta.extra.insert(
                "capture".into(),
                json!({ "angles": paths.map(|p| p.display().to_string()) }),
            );
            (pol, bits)
        }
        (None, None) => return Err("give --mosaic RAW.png or --angles P0 P45 P90 P135".into()),
    };
    if let Some(b) = a.sensor_bits {
        meta.extra.insert("sensor_bits".into(), json!(b));
    }
    let mask = match (&a.mask, &a.window) {
        (Some(path), _) => MaskSource::File(capture::read_mask(path)?),
        (None, Some(w)) => match w[..] {
            [low, high] => MaskSource::Window(low, high),
            _ => return Err(format!("--window takes LOW,HIGH, got {} values", w.len()).into()),
        },
        (None, None) => MaskSource::All,
    };
    let (view, summary) = capture::view_from_images(pol, bits, a.sensor_bits, &mask, meta)?;
    view.write(&a.out)?;
    if let Some(agreement) = summary.silhouette_aop.filter(|&v| v < capture::TURNED_AOP) {
        let fix = match (&a.mosaic, Pattern::parse(&a.pattern)) {
            (Some(_), Ok(pattern)) => format!("--pattern {} fits it", pattern.turned_90()),
            _ => "the 0° and 90° (and 45° and 135°) images look swapped".to_string(),
        };
        eprintln!(
            "warning: the AoP along the object's outline is turned by 90° from its outward \
             direction (mean cos 2Δ = {agreement:.2}); for a matte object that means the \
             polarizer angles are off by 90°: {fix}"
        );
    }
    print_summary(&a.out, &view, Some(&summary))
}

/// The imported view's size, bit depth, mask and polarimetry, as JSON.
fn print_summary(out: &Path, view: &View, capture: Option<&CaptureSummary>) -> CliResult {
    let (width, height) = view.input.size();
    println!(
        "{}",
        serde_json::to_string_pretty(&json!({
            "view": out.display().to_string(),
            "width": width,
            "height": height,
            "bits": view.input.bits,
            "saturated_pixels": capture.map(|c| c.saturated),
            "dop_above_one_pixels": capture.map(|c| c.impossible_dop),
            "silhouette_aop_agreement": capture.and_then(|c| c.silhouette_aop),
            "mask_pixels": view.input.mask.as_ref().map_or(width * height, |m| m.count()),
            "ground_truth": view.gt.is_some(),
            "polarimetry": sfp_core::inspect::summarize(view),
        }))?
    );
    Ok(())
}
