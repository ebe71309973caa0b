//! `sfp import`: a real capture (a division-of-focal-plane raw frame, or four
//! polarizer images) as a view folder.

use crate::CliResult;
use serde_json::json;
use sfp_core::capture::{self, CaptureSummary, MaskSource};
use sfp_core::export;
use sfp_core::io;
use sfp_core::mosaic::{Demosaic, Pattern, demosaic};
use sfp_core::pattern_check::PatternCheck;
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
#[command(
    after_help = "The import checks the capture against its labels: I0 + I90 = I45 + I135 \
must hold within the sensor's noise, and with an object mask the AoP along the outline must \
follow the outward direction. When the data fit other labels it warns and names the --pattern \
(or --angles order) that fits; the figures are in meta.json (pattern_check).\n\n\
--auto-mask: intensity split by Otsu's threshold (the side on the image border is background), \
or DoP (pixels above 2% of full scale) above its Otsu threshold when the border is unpolarized; \
the largest connected piece with its holes filled."
)]
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
    #[arg(
        long,
        value_name = "LOW,HIGH",
        value_delimiter = ',',
        conflicts_with = "auto_mask"
    )]
    window: Option<Vec<f64>>,
    /// Sensor bit depth when below the file's (e.g. 12 for 12-bit data in
    /// 16-bit PNGs): sets the saturation code.
    #[arg(long, value_name = "BITS", allow_negative_numbers = true)]
    sensor_bits: Option<u8>,
    /// Output view folder.
    #[arg(long)]
    out: PathBuf,
}

/// Where the four images came from, to name the labels that fit them.
enum Source<'a> {
    /// A mosaic with this pattern.
    Mosaic(Pattern),
    /// Files as given.
    Angles(&'a [PathBuf]),
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
    let mut record = json!({});
    let (pol, bits, source) = match (&a.mosaic, &a.angles) {
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
            record["mosaic"] = json!(raw.display().to_string());
            record["pattern"] = json!(a.pattern);
            record["demosaic"] = json!(format!("{method:?}"));
            (pol, bits, Source::Mosaic(pattern))
        }
        (None, Some(paths)) => {
            let files: [&Path; 4] = std::array::from_fn(|k| paths[k].as_path());
            let (pol, bits) = capture::read_four(&files)?;
            record["angles"] = json!(
                paths
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
            );
            (pol, bits, Source::Angles(paths))
        }
        (None, None) => return Err("give --mosaic RAW.png or --angles P0 P45 P90 P135".into()),
    };
    meta.extra.insert("capture".into(), record);
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
    let check = &summary.pattern;
    if !check.labelled_fits() {
        warn_misfit(check, &source);
    }
    print_summary(&a.out, &view, Some(&summary))
}

/// Warns that the images do not fit their labels, naming the `--pattern` or
/// `--angles` order that fits.
fn warn_misfit(check: &PatternCheck, source: &Source) {
    let fixes: Vec<String> = check
        .fits
        .iter()
        .map(|order| match source {
            Source::Mosaic(pattern) => {
                let inverse = order.inverse();
                format!("--pattern {}", pattern.relabel(|k| inverse[k]))
            }
            Source::Angles(paths) => {
                let files: Vec<String> = (0..4)
                    .map(|a| paths[order.0[a]].display().to_string())
                    .collect();
                format!("--angles {}", files.join(" "))
            }
        })
        .collect();
    let reason = if !check.labelled_split_fits() {
        format!(
            "I0 + I90 differs from I45 + I135 far beyond the noise (RMS {:.4} of s0; \
             the pairing that fits leaves {:.4})",
            check.sum_rule[1],
            check.noise()
        )
    } else {
        format!(
            "the AoP does not follow the object's outline as a matte object's does \
             (mean cos 2Δ = {:.2})",
            check.silhouette.unwrap_or(f64::NAN)
        )
    };
    let unchecked = if check.oriented {
        ""
    } else {
        " (the images' orientation is unchecked: give --mask so the AoP along the \
         object's outline can decide)"
    };
    eprintln!(
        "warning: the polarizer images are not at the angles they are labelled with: {reason}. \
         {} fits the data{unchecked}",
        fixes.join(" or ")
    );
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
            "silhouette_aop_agreement": capture.and_then(|c| c.pattern.silhouette),
            "pattern_check": capture.map(|c| c.pattern.to_json()),
            "mask_pixels": view.input.mask.as_ref().map_or(width * height, |m| m.count()),
            "ground_truth": view.gt.is_some(),
            "polarimetry": sfp_core::inspect::summarize(view),
        }))?
    );
    Ok(())
}
