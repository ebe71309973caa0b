//! `sfp import`: a real capture (a division-of-focal-plane raw frame, or four
//! polarizer images) as a view folder.

use crate::exit::CliResult;
use clap::ValueEnum;
use serde_json::json;
use sfp_core::Image;
use sfp_core::angle_frame::AngleFrame;
use sfp_core::calibration::{self, Frame};
use sfp_core::capture::{self, CaptureSummary, MaskSource};
use sfp_core::export;
use sfp_core::io;
use sfp_core::mosaic::{Demosaic, Pattern, demosaic, unused_edge};
use sfp_core::pattern_check::PatternCheck;
use sfp_core::view::{Meta, View};
use sfp_reconstruct::input::Input;
use sfp_reconstruct::specular::beyond_diffuse::BeyondDiffuse;
use std::path::{Path, PathBuf};

#[derive(clap::ValueEnum, Clone, Copy)]
enum Method {
    /// One pixel per 2×2 cell (half resolution, no interpolation).
    Superpixel,
    /// Full resolution, each missing value the mean of its nearest photosites.
    Bilinear,
}

#[derive(clap::ValueEnum, Clone, Copy, Default)]
enum AnglesFrom {
    /// From the horizontal (image right), counter-clockwise, as conventions.md §1.
    #[default]
    HorizontalCcw,
    /// From the vertical (image up), clockwise: 0° is vertical, 90° horizontal.
    VerticalCw,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["mosaic", "angles", "layout"])))]
#[command(
    after_help = "The import checks the capture against its labels: I0 + I90 = I45 + I135 \
must hold within the sensor's noise, and with an object mask the AoP along the outline must \
follow the outward direction. When the data fit other labels it warns and names the --pattern \
(or --angles order) that fits; the figures are in meta.json (pattern_check).\n\n\
--auto-mask: pixels whose polarization differs from the background's (fitted on the image \
border) in most of their 5×5 window, or the intensity side of Otsu's threshold not on the border \
when 90% of the border lies on one side; connected pieces of at least a tenth of the largest, \
holes filled."
)]
pub struct Args {
    /// Raw frame of a division-of-focal-plane polarization sensor (8/16-bit PNG).
    #[arg(long, value_name = "RAW.png")]
    mosaic: Option<PathBuf>,
    /// Polarizer angles of a 2×2 mosaic cell in reading order.
    #[arg(long, default_value = "90,45,135,0", requires = "mosaic")]
    pattern: String,
    /// How the mosaic is demosaiced (superpixel drops an odd last column or
    /// row, with a warning and a note in meta.json).
    #[arg(long, value_enum, default_value = "superpixel", requires = "mosaic")]
    demosaic: Method,
    /// Four images behind polarizers at 0°, 45°, 90° and 135°, in that order.
    #[arg(long, num_args = 4, value_names = ["P0", "P45", "P90", "P135"])]
    angles: Option<Vec<PathBuf>>,
    /// How the angles of --pattern and --angles are measured.
    #[arg(long, value_enum, default_value = "horizontal-ccw")]
    angles_from: AnglesFrom,
    /// A per-angle layout folder (pol000/ pol045/ pol090/ pol135/, optional
    /// mask/ and normal/, as `sfp export` writes it): imports one view with
    /// its mask and ground-truth normals.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["mask", "window", "auto_mask", "sensor_bits", "dark", "flat"])]
    layout: Option<PathBuf>,
    /// Which view of the layout (its file name without .png); needed when it holds several.
    #[arg(long, requires = "layout")]
    name: Option<String>,
    /// Object mask image (non-zero = object), same size as the polarizer images.
    #[arg(long, conflicts_with_all = ["window", "auto_mask"])]
    mask: Option<PathBuf>,
    /// Object = pixels whose mean polarizer code lies in LOW,HIGH (fractions of full scale).
    #[arg(
        long,
        value_name = "LOW,HIGH",
        value_delimiter = ',',
        allow_hyphen_values = true,
        conflicts_with = "auto_mask"
    )]
    window: Option<Vec<f64>>,
    /// Object mask found from intensity and DoP (see below).
    #[arg(long)]
    auto_mask: bool,
    /// Dark frame (same sensor, size and bit depth as the raw frame or each
    /// polarizer image), subtracted.
    #[arg(long, value_name = "FRAME.png")]
    dark: Option<PathBuf>,
    /// Flat field (a uniformly lit unpolarized frame, same size and bit
    /// depth), divided out after normalizing it by its mean.
    #[arg(long, value_name = "FRAME.png")]
    flat: Option<PathBuf>,
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
    /// A mosaic with this pattern (in the project's angle frame).
    Mosaic(Pattern),
    /// Files as given, in the user's label order.
    Angles(&'a [PathBuf]),
}

pub fn run(a: Args) -> CliResult {
    let mut meta = Meta::new("sfp import");
    let frame = match a.angles_from {
        AnglesFrom::HorizontalCcw => AngleFrame::HorizontalCcw,
        AnglesFrom::VerticalCw => AngleFrame::VerticalCw,
    };
    let to_ours = |k: usize| frame.standard_index(k);
    if let Some(dir) = &a.layout {
        return import_layout(&a, dir, meta, &to_ours);
    }
    let dark = a.dark.as_deref().map(Frame::read).transpose()?;
    let flat = a.flat.as_deref().map(Frame::read).transpose()?;
    let warned = std::cell::Cell::new(false);
    let correct = |img: Image<u16>, bits: u8| -> sfp_core::Result<Image<u16>> {
        if dark.is_none() && flat.is_none() {
            return Ok(img);
        }
        let full = capture::full_scale(bits, a.sensor_bits)?;
        let corrected = calibration::correct(&img, bits, full, dark.as_ref(), flat.as_ref())?;
        // A dark frame as bright as the capture (a frame of another
        // exposure, or the capture itself) leaves nothing to reconstruct.
        let wiped = (img.data().iter().zip(corrected.data()))
            .filter(|&(&before, &after)| before > 0 && after == 0)
            .count();
        if let Some(d) = &a.dark
            && wiped * 2 > img.len()
            && !warned.replace(true)
        {
            eprintln!(
                "warning: {}: subtracting this dark frame leaves {wiped} of {} pixels at 0: \
                 is it a dark frame of this capture's exposure?",
                d.display(),
                img.len()
            );
        }
        Ok(corrected)
    };
    let frame_name = a.angles_from.to_possible_value().expect("a named frame");
    let mut record = json!({
        "angles_from": frame_name.get_name(),
        "dark": a.dark.as_ref().map(|p| p.display().to_string()),
        "flat": a.flat.as_ref().map(|p| p.display().to_string()),
    });
    let (pol, bits, source) = match (&a.mosaic, &a.angles) {
        (Some(raw), _) => {
            let pattern = Pattern::parse(&a.pattern)?.relabel(to_ours);
            let method = match a.demosaic {
                Method::Superpixel => Demosaic::SuperPixel,
                Method::Bilinear => Demosaic::Bilinear,
            };
            let frame = io::read_mono_png(raw)?;
            let bits = frame.bits();
            let frame = correct(frame.into_u16(), bits)?;
            let (w, h) = frame.size();
            let pol =
                demosaic(&frame, pattern, method).map_err(|e| format!("{}: {e}", raw.display()))?;
            let (columns, rows) = unused_edge(w, h, method);
            if columns + rows > 0 {
                eprintln!(
                    "warning: {}: the {w}×{h} frame has an odd last {}; the superpixel \
                     demosaic leaves it out (--demosaic bilinear keeps it)",
                    raw.display(),
                    match (columns, rows) {
                        (1, 1) => "column and row",
                        (1, _) => "column",
                        _ => "row",
                    }
                );
            }
            record["mosaic"] = json!(raw.display().to_string());
            record["pattern"] = json!(a.pattern);
            record["demosaic"] = json!(format!("{method:?}"));
            record["unused_edge"] = json!({ "columns": columns, "rows": rows });
            (pol, bits, Source::Mosaic(pattern))
        }
        (None, Some(paths)) => {
            // Image k (the project's angle k) is the file labelled to_ours(k).
            let files: [&Path; 4] = std::array::from_fn(|k| paths[to_ours(k)].as_path());
            let (pol, bits) = capture::read_four(&files)?;
            let mut corrected = Vec::with_capacity(4);
            for img in pol {
                corrected.push(correct(img, bits)?);
            }
            let pol: [Image<u16>; 4] = corrected.try_into().expect("four images");
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
        (None, None) if a.auto_mask => MaskSource::Auto,
        (None, None) => MaskSource::All,
    };
    let (mut view, summary) = capture::view_from_images(pol, bits, a.sensor_bits, &mask, meta)?;
    let beyond = view
        .input
        .mask
        .is_some()
        .then(|| {
            // `Input::new`: an import is not refused for what a method cannot use.
            let input = Input::new(view.input.polarimetry(), view.input.mask.clone())?;
            Ok::<_, sfp_core::Error>(BeyondDiffuse::of(&input))
        })
        .transpose()?;
    if let (Some(beyond), Some(meta)) = (beyond, view.meta.as_mut()) {
        meta.extra
            .insert("beyond_diffuse".into(), serde_json::to_value(beyond)?);
    }
    view.write(&a.out)?;
    if let Some(warning) = beyond.and_then(|b| b.warning()) {
        eprintln!("warning: {}: {warning}", a.out.display());
    }
    let check = &summary.pattern;
    if !check.labelled_fits() {
        warn_misfit(check, &source, to_ours);
    }
    print_summary(&a.out, &view, Some(&summary))
}

/// A view of a per-angle layout, checked as every other import is (sum
/// rule, orientation along the mask's outline, saturation, DoP above 1,
/// an empty mask) and relabelled by `--angles-from`; its ground truth comes
/// with it.
fn import_layout(
    a: &Args,
    dir: &Path,
    mut meta: Meta,
    to_ours: &dyn Fn(usize) -> usize,
) -> CliResult {
    let name = export::layout_name(dir, a.name.as_deref())?;
    let layout = export::read_layout(dir, Some(&name))?;
    let files = export::layout_files(dir, &name);
    let pol = std::array::from_fn(|k| layout.input.pol[to_ours(k)].clone());
    let frame_name = a.angles_from.to_possible_value().expect("a named frame");
    meta.extra.insert(
        "capture".into(),
        json!({
            "layout": dir.display().to_string(),
            "name": name,
            "angles_from": frame_name.get_name(),
        }),
    );
    let mask = match layout.input.mask {
        Some(m) => MaskSource::File(m),
        None => MaskSource::All,
    };
    let (mut view, summary) = capture::view_from_images(pol, layout.input.bits, None, &mask, meta)
        .map_err(|e| format!("{} (view {name:?}): {e}", dir.display()))?;
    view.gt = layout.gt;
    view.write(&a.out)?;
    if !summary.pattern.labelled_fits() {
        warn_misfit(&summary.pattern, &Source::Angles(&files), to_ours);
    }
    print_summary(&a.out, &view, Some(&summary))
}

/// Warns that the images do not fit their labels, naming the `--pattern` or
/// `--angles` order (in the user's angle frame, `to_ours` maps it) that fits.
fn warn_misfit(check: &PatternCheck, source: &Source, to_ours: impl Fn(usize) -> usize) {
    let fixes: Vec<String> = check
        .fits
        .iter()
        .map(|order| match source {
            Source::Mosaic(pattern) => {
                let inverse = order.inverse();
                format!("--pattern {}", pattern.relabel(|k| to_ours(inverse[k])))
            }
            Source::Angles(paths) => {
                let files: Vec<String> = (0..4)
                    .map(|b| paths[to_ours(order.0[to_ours(b)])].display().to_string())
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
    let unchecked = match (check.oriented, check.silhouette) {
        (true, _) => "",
        (false, Some(_)) => {
            " (the images' orientation is unchecked: the AoP along the object's outline \
             follows no single order clearly)"
        }
        (false, None) => {
            " (the images' orientation is unchecked: give --mask or --auto-mask so the AoP \
             along the object's outline can decide)"
        }
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
    outln!(
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
    )?;
    Ok(())
}
