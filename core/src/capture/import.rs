//! The import of a capture: the one pipeline `sfp import` and Python's
//! `import_mosaic`/`import_angles` run, from the sensor's frames to the view
//! and what the import found. Dark frame and flat field are corrected on
//! the frames as the sensor gave them (the raw mosaic, or each polarizer
//! image); the labels are mapped from the camera's angle frame to the
//! project's before anything else sees them; the mask is formed and the
//! labels checked by [`view_from_images`](crate::capture::view_from_images).
//!
//! Warnings are handed to the caller as they arise, so a warning given
//! before a refusal is still seen.

use crate::capture::angle_frame::AngleFrame;
use crate::capture::calibration;
use crate::capture::frame::Frame;
use crate::capture::mosaic::{
    Bayer, Demosaic, Pattern, demosaic, demosaic_colour, unused_edge, unused_edge_colour,
};
use crate::capture::pattern_check::PatternCheck;
use crate::capture::{self, CaptureSummary, MaskSource};
use crate::export;
use crate::prediction::Axes;
use crate::view::{Meta, View, ViewInput};
use crate::{Error, Image, Result};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Where the four polarizer images come from.
#[derive(Clone, Debug)]
pub enum Source {
    /// The raw frame of a division-of-focal-plane sensor.
    Mosaic(Frame),
    /// Four images labelled 0°, 45°, 90°, 135° (in the options' angle frame).
    Angles(Box<[Frame; 4]>),
    /// One view of a per-angle layout folder (as `sfp export` writes it),
    /// with its mask and ground truth; `name` is needed when it holds several.
    Layout { dir: PathBuf, name: Option<String> },
}

/// Every choice of an import, as `sfp import` takes them.
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// Polarizer angles of a 2×2 mosaic cell in reading order, as given
    /// (and recorded); mosaics only.
    pub pattern: String,
    /// How a mosaic is demosaiced.
    pub demosaic: Demosaic,
    /// The colour filters' Bayer order of a colour mosaic (IMX250MYR:
    /// each 2×2 polarizer cell under one filter); `None`: a mono mosaic.
    pub colour: Option<Bayer>,
    /// How the angles of `pattern` and of the four images are measured.
    pub angles_from: AngleFrame,
    /// How the object mask is formed (not for a layout, which brings its own).
    pub mask: MaskSource,
    /// Dark frame subtracted from every frame of the capture.
    pub dark: Option<Frame>,
    /// Flat field divided out after the dark frame.
    pub flat: Option<Frame>,
    /// The sensor's bit depth when below the file's: sets the saturation code.
    pub sensor_bits: Option<u8>,
    /// The frame of a layout's ground-truth normals (layouts only).
    pub axes: Axes,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            pattern: Pattern::SONY.to_string(),
            demosaic: Demosaic::default(),
            colour: None,
            angles_from: AngleFrame::default(),
            mask: MaskSource::default(),
            dark: None,
            flat: None,
            sensor_bits: None,
            axes: Axes::Ours,
        }
    }
}

/// The labels the images came with, to name the ones that fit the data.
#[derive(Clone, Debug)]
enum Labels {
    /// A mosaic with this pattern (in the project's angle frame).
    Mosaic(Pattern),
    /// Images named in the user's label order.
    Angles([PathBuf; 4]),
}

/// An imported capture: the view (not yet written) and what the import found.
#[derive(Clone, Debug)]
pub struct Imported {
    pub view: View,
    pub summary: CaptureSummary,
    labels: Labels,
    angles_from: AngleFrame,
    layout: bool,
}

/// Imports `source` as `options` say, handing each warning to `warn`.
pub fn import(
    source: &Source,
    options: &ImportOptions,
    warn: &mut dyn FnMut(String),
) -> Result<Imported> {
    let frame = options.angles_from;
    let to_ours = |k: usize| frame.standard_index(k);
    let mut meta = Meta::new("sfp import");
    let mut colour = None;
    let (pol, bits, labels) = match source {
        Source::Layout { dir, name } => {
            return import_layout(dir, name.as_deref(), options, meta, warn);
        }
        Source::Mosaic(raw) => {
            let pattern = Pattern::parse(&options.pattern)?.relabel(to_ours);
            let method = options.demosaic;
            let bits = raw.bits;
            let corrected = correct(raw.image.clone(), bits, options, &mut false, warn)?;
            let (w, h) = corrected.size();
            let in_file = |e: Error| Error::file(&raw.path, e.to_string());
            let (pol, (columns, rows)) = match options.colour {
                None => (
                    demosaic(&corrected, pattern, method).map_err(in_file)?,
                    unused_edge(w, h, method),
                ),
                Some(bayer) => {
                    let rgb =
                        demosaic_colour(&corrected, pattern, bayer, method).map_err(in_file)?;
                    let grey = ViewInput::of_colour(rgb.clone(), bits, None).pol;
                    colour = Some(rgb);
                    (grey, unused_edge_colour(w, h, method))
                }
            };
            if columns + rows > 0 {
                let what = match (options.colour, columns, rows) {
                    (Some(_), c, r) => {
                        format!("{c} columns and {r} rows beyond its last complete 4×4 block")
                    }
                    (None, 1, 1) => "an odd last column and row".into(),
                    (None, 1, _) => "an odd last column".into(),
                    (None, ..) => "an odd last row".into(),
                };
                warn(format!(
                    "{}: the {w}×{h} frame has {what}; the superpixel demosaic leaves it out \
                     (--demosaic bilinear keeps it)",
                    raw.path.display(),
                ));
            }
            let mut record = record(options);
            record["mosaic"] = json!(raw.path.display().to_string());
            record["pattern"] = json!(options.pattern);
            record["demosaic"] = json!(format!("{method:?}"));
            if let Some(bayer) = options.colour {
                record["colour"] = json!(bayer.name());
            }
            record["unused_edge"] = json!({ "columns": columns, "rows": rows });
            meta.extra.insert("capture".into(), record);
            (pol, bits, Labels::Mosaic(pattern))
        }
        Source::Angles(frames) => {
            // Image k (the project's angle k) is the frame labelled to_ours(k).
            let ordered: [Frame; 4] = std::array::from_fn(|k| frames[to_ours(k)].clone());
            let coloured = ordered.iter().filter(|f| f.colour.is_some()).count();
            if coloured > 0 {
                // The odd one out is named: one grey among colour images, or
                // one colour picture among grey ones.
                let odd = ordered
                    .iter()
                    .find(|f| f.colour.is_some() == (coloured < 2))
                    .filter(|_| coloured < 4);
                if let Some(odd) = odd {
                    let (this, others) = if coloured < 2 {
                        ("an RGB picture", "grey")
                    } else {
                        ("a grey image", "colour")
                    };
                    return Err(Error::file(
                        &odd.path,
                        format!(
                            "{this}, but the other polarizer images are {others}: give four \
                             grey images, or four RGB ones for a colour view"
                        ),
                    ));
                }
                if options.dark.is_some() || options.flat.is_some() {
                    return Err(Error::file(
                        &ordered[0].path,
                        "is a colour image: dark frame and flat field are corrected on grey \
                         or mosaic frames only",
                    ));
                }
                colour = Some(
                    ordered
                        .each_ref()
                        .map(|f| f.colour.clone().expect("colour")),
                );
            }
            let (pol, bits) = capture::four(ordered)?;
            let mut corrected = Vec::with_capacity(4);
            let mut warned = false;
            for img in pol {
                corrected.push(correct(img, bits, options, &mut warned, warn)?);
            }
            let pol: [Image<u16>; 4] = corrected.try_into().expect("four images");
            let paths = frames.each_ref().map(|f| f.path.clone());
            let mut record = record(options);
            record["angles"] = json!(paths.each_ref().map(|p| p.display().to_string()));
            meta.extra.insert("capture".into(), record);
            (pol, bits, Labels::Angles(paths))
        }
    };
    if let Some(b) = options.sensor_bits {
        meta.extra.insert("sensor_bits".into(), json!(b));
    }
    let (view, summary) = match colour {
        Some(rgb) => {
            capture::view_from_colour(rgb, bits, options.sensor_bits, &options.mask, meta)?
        }
        None => capture::view_from_images(pol, bits, options.sensor_bits, &options.mask, meta)?,
    };
    Ok(Imported {
        view,
        summary,
        labels,
        angles_from: frame,
        layout: false,
    })
}

/// The `capture` record of `meta.json` before the source's own keys.
fn record(options: &ImportOptions) -> serde_json::Value {
    json!({
        "angles_from": options.angles_from.name(),
        "dark": options.dark.as_ref().map(|f| f.path.display().to_string()),
        "flat": options.flat.as_ref().map(|f| f.path.display().to_string()),
    })
}

/// `img` with the dark frame and flat field of `options` applied (as it
/// is without them), warning when the dark frame wipes most of it unless
/// `warned` says it was said for another image of the capture.
fn correct(
    img: Image<u16>,
    bits: u8,
    options: &ImportOptions,
    warned: &mut bool,
    warn: &mut dyn FnMut(String),
) -> Result<Image<u16>> {
    let (dark, flat) = (options.dark.as_ref(), options.flat.as_ref());
    if dark.is_none() && flat.is_none() {
        return Ok(img);
    }
    let full = capture::full_scale(bits, options.sensor_bits)?;
    let corrected = calibration::correct(&img, bits, full, dark, flat)?;
    // A dark frame as bright as the capture (a frame of another exposure,
    // or the capture itself) leaves nothing to reconstruct.
    let wiped = (img.data().iter().zip(corrected.data()))
        .filter(|&(&before, &after)| before > 0 && after == 0)
        .count();
    if let Some(d) = dark
        && wiped * 2 > img.len()
        && !std::mem::replace(warned, true)
    {
        warn(format!(
            "{}: subtracting this dark frame leaves {wiped} of {} pixels at 0: \
             is it a dark frame of this capture's exposure?",
            d.path.display(),
            img.len()
        ));
    }
    Ok(corrected)
}

/// A view of a per-angle layout, checked as every other import is (sum
/// rule, orientation along the mask's outline, saturation, DoP above 1,
/// an empty mask) and relabelled by the angle frame; its ground truth comes
/// with it.
fn import_layout(
    dir: &Path,
    name: Option<&str>,
    options: &ImportOptions,
    mut meta: Meta,
    warn: &mut dyn FnMut(String),
) -> Result<Imported> {
    if options.dark.is_some()
        || options.flat.is_some()
        || options.sensor_bits.is_some()
        || options.mask != MaskSource::All
    {
        return Err(Error::file(
            dir,
            "a layout brings its own mask and is imported without dark frame, flat field, \
             sensor depth or mask choice",
        ));
    }
    let frame = options.angles_from;
    let to_ours = |k: usize| frame.standard_index(k);
    let name = export::layout_name(dir, name)?;
    let layout = export::read_layout(dir, Some(&name), options.axes)?;
    for problem in &layout.problems {
        warn(problem.clone());
    }
    let pol = std::array::from_fn(|k| layout.input.pol[to_ours(k)].clone());
    let colour =
        (layout.input.colour.as_ref()).map(|rgb| std::array::from_fn(|k| rgb[to_ours(k)].clone()));
    meta.extra.insert(
        "capture".into(),
        json!({
            "layout": dir.display().to_string(),
            "name": name,
            "angles_from": frame.name(),
            "normals_axes": options.axes.name(),
        }),
    );
    let mask = match layout.input.mask {
        Some(m) => MaskSource::File(m),
        None => MaskSource::All,
    };
    let bits = layout.input.bits;
    let (mut view, summary) = match colour {
        Some(rgb) => capture::view_from_colour(rgb, bits, None, &mask, meta),
        None => capture::view_from_images(pol, bits, None, &mask, meta),
    }
    .map_err(|e| Error::invalid(format!("{} (view {name:?}): {e}", dir.display())))?;
    view.gt = layout.gt;
    Ok(Imported {
        view,
        summary,
        labels: Labels::Angles(export::layout_files(dir, &name)),
        angles_from: frame,
        layout: true,
    })
}

impl Imported {
    /// Whether the view came from a per-angle layout.
    pub fn from_layout(&self) -> bool {
        self.layout
    }

    /// The warning that the images do not fit their labels, naming the
    /// `--pattern` or `--angles` order (in the user's angle frame) that fits;
    /// None when the labels fit.
    pub fn misfit_warning(&self) -> Option<String> {
        let check = &self.summary.pattern;
        (!check.labelled_fits()).then(|| misfit(check, &self.labels, self.angles_from))
    }
}

fn misfit(check: &PatternCheck, labels: &Labels, frame: AngleFrame) -> String {
    let to_ours = |k: usize| frame.standard_index(k);
    let fixes: Vec<String> = check
        .fits
        .iter()
        .map(|order| match labels {
            Labels::Mosaic(pattern) => {
                let inverse = order.inverse();
                format!("--pattern {}", pattern.relabel(|k| to_ours(inverse[k])))
            }
            Labels::Angles(paths) => {
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
    format!(
        "the polarizer images are not at the angles they are labelled with: {reason}. \
         {} fits the data{unchecked}",
        fixes.join(" or ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(name: &str, image: Image<u16>) -> Frame {
        Frame {
            colour: None,
            path: PathBuf::from(name),
            image,
            bits: 8,
        }
    }

    #[test]
    fn a_layout_takes_no_calibration_and_no_mask_choice() {
        let layout = Source::Layout {
            dir: PathBuf::from("layout"),
            name: None,
        };
        let options = ImportOptions {
            dark: Some(frame("dark.png", Image::new(2, 2, 0))),
            ..ImportOptions::default()
        };
        let e = import(&layout, &options, &mut |_| {}).unwrap_err();
        assert!(e.to_string().starts_with("layout: a layout brings"), "{e}");
    }

    #[test]
    fn warnings_are_handed_over_before_a_refusal() {
        // An odd 5×4 mosaic whose codes exceed a 6-bit sensor: the edge
        // warning comes, then the refusal.
        let raw = frame(
            "raw.png",
            Image::from_fn(5, 4, |x, y| (10 * x + y) as u16 + 60),
        );
        let options = ImportOptions {
            sensor_bits: Some(6),
            ..ImportOptions::default()
        };
        let mut said = Vec::new();
        let e = import(&Source::Mosaic(raw), &options, &mut |w| said.push(w)).unwrap_err();
        assert!(e.to_string().contains("6-bit"), "{e}");
        assert_eq!(said.len(), 1);
        assert!(said[0].starts_with("raw.png: the 5×4 frame has an odd last column;"));
    }
}
