//! `sfp import`: a real capture (a division-of-focal-plane raw frame, or four
//! polarizer images) as a view folder. The import itself is the library's
//! (`sfp_reconstruct::capture_import`); this file reads the arguments and
//! prints what the import found.

use crate::exit::CliResult;
use serde_json::json;
use sfp_core::capture::angle_frame::AngleFrame;
use sfp_core::capture::frame::Frame;
use sfp_core::capture::import::{ImportOptions, Source};
use sfp_core::capture::mosaic::{Bayer, Demosaic};
use sfp_core::capture::{self, CaptureSummary, MaskSource};
use sfp_core::prediction::Axes;
use sfp_core::view::View;
use sfp_reconstruct::capture_import;
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
    /// row, with a warning and a note in meta.json; of a colour mosaic, one
    /// pixel per 4×4 block).
    #[arg(long, value_enum, default_value = "superpixel", requires = "mosaic")]
    demosaic: Method,
    /// A colour mosaic (Sony IMX250MYR: each 2×2 polarizer cell under one
    /// colour filter) with its cells in this Bayer order: rggb, bggr, grbg
    /// or gbrg. The view keeps its colour.
    #[arg(long, value_name = "ORDER", requires = "mosaic", value_parser = parse_bayer)]
    colour: Option<Bayer>,
    /// Four images behind polarizers at 0°, 45°, 90° and 135°, in that order
    /// (grey, or RGB for a colour view).
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
    /// The frame of the layout's normals: ours (x right, y up, z towards the
    /// camera), image (y down) or opencv (y down, z into the scene); the
    /// import warns when they fit the other y sense along the mask's outline.
    #[arg(long, requires = "layout", default_value = "ours", value_parser = crate::values::parse_axes)]
    axes: Axes,
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

impl Args {
    /// The source and the options of the library's import (files read).
    fn import(&self) -> sfp_core::Result<(Source, ImportOptions)> {
        let dark = self.dark.as_deref().map(Frame::read).transpose()?;
        let flat = self.flat.as_deref().map(Frame::read).transpose()?;
        let source = match (&self.layout, &self.mosaic, &self.angles) {
            (Some(dir), ..) => Source::Layout {
                dir: dir.clone(),
                name: self.name.clone(),
            },
            (None, Some(raw), _) => Source::Mosaic(Frame::read(raw)?),
            (None, None, Some(paths)) => {
                let mut frames = Vec::with_capacity(4);
                for path in paths {
                    frames.push(Frame::read_polarizer(path)?);
                }
                Source::Angles(Box::new(frames.try_into().expect("clap takes four")))
            }
            (None, None, None) => {
                return Err(sfp_core::Error::invalid(
                    "give --mosaic RAW.png or --angles P0 P45 P90 P135",
                ));
            }
        };
        let mask = match (&self.mask, &self.window) {
            (Some(path), _) => MaskSource::File(capture::read_mask(path)?),
            (None, Some(w)) => match w[..] {
                [low, high] => MaskSource::Window(low, high),
                _ => {
                    return Err(sfp_core::Error::invalid(format!(
                        "--window takes LOW,HIGH, got {} values",
                        w.len()
                    )));
                }
            },
            (None, None) if self.auto_mask => MaskSource::Auto,
            (None, None) => MaskSource::All,
        };
        let options = ImportOptions {
            pattern: self.pattern.clone(),
            demosaic: match self.demosaic {
                Method::Superpixel => Demosaic::SuperPixel,
                Method::Bilinear => Demosaic::Bilinear,
            },
            colour: self.colour,
            angles_from: match self.angles_from {
                AnglesFrom::HorizontalCcw => AngleFrame::HorizontalCcw,
                AnglesFrom::VerticalCw => AngleFrame::VerticalCw,
            },
            mask,
            dark,
            flat,
            sensor_bits: self.sensor_bits,
            axes: self.axes,
        };
        Ok((source, options))
    }
}

fn parse_bayer(text: &str) -> Result<Bayer, String> {
    Bayer::parse(text).map_err(|e| e.to_string())
}

pub fn run(a: Args) -> CliResult {
    let (source, options) = a.import()?;
    let mut warn = |w: String| eprintln!("warning: {w}");
    let imported = capture_import::import(&source, &options, Some(&a.out), &mut warn)?;
    print_summary(&a.out, &imported.view, &imported.summary)
}

/// The imported view's size, bit depth, mask and polarimetry, as JSON.
fn print_summary(out: &Path, view: &View, capture: &CaptureSummary) -> CliResult {
    let (width, height) = view.input.size();
    outln!(
        "{}",
        serde_json::to_string_pretty(&json!({
            "view": out.display().to_string(),
            "width": width,
            "height": height,
            "bits": view.input.bits,
            "saturated_pixels": capture.saturated,
            "dop_above_one_pixels": capture.impossible_dop,
            "silhouette_aop_agreement": capture.pattern.silhouette,
            "pattern_check": capture.pattern.to_json(),
            "mask_pixels": view.input.mask.as_ref().map_or(width * height, |m| m.count()),
            "ground_truth": view.gt.is_some(),
            "polarimetry": sfp_core::inspect::summarize(view),
        }))?
    )?;
    Ok(())
}
