//! A real capture as a view (conventions.md §5, no `gt/`): four polarizer
//! images from a division-of-focal-plane raw frame ([`mosaic`]) or from four
//! separate exposures, with an object mask. The steps of an import live
//! beside it: the sensor's frames ([`frame`]), dark frame and flat field
//! ([`calibration`]), the camera's angle convention ([`angle_frame`]), the
//! automatic mask ([`auto_mask`]), the labels checked against the data
//! ([`pattern_check`]) and the one pipeline chaining them ([`import`]).
//!
//! Saturated pixels (any polarizer at full scale) are left out of the mask:
//! clipping one polarizer bends the fitted Stokes vector, so their DoP and
//! AoP are wrong, not just noisy.

pub mod angle_frame;
pub mod auto_mask;
pub mod calibration;
pub mod frame;
pub mod import;
pub mod mosaic;
pub mod pattern_check;

use crate::capture::auto_mask::auto_mask;
use crate::capture::frame::Frame;
use crate::capture::pattern_check::PatternCheck;
use crate::io;
use crate::stokes::Stokes;
use crate::view::{Meta, View, ViewInput};
use crate::{Error, Image, Mask, Result};
use std::path::Path;

/// How the object mask of an imported capture is formed.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum MaskSource {
    /// Every unsaturated pixel (no mask file when nothing saturates).
    #[default]
    All,
    /// A mask image (8- or 16-bit, non-zero = object), unsaturated pixels of it.
    File(Image<bool>),
    /// Unsaturated pixels whose mean polarizer code, as a fraction of full
    /// scale, lies in `[low, high]` (e.g. a dark object on a bright sheet).
    Window(f64, f64),
    /// Found from intensity and DoP by the rule of [`auto_mask`](crate::capture::auto_mask)
    /// (unsaturated pixels of it).
    Auto,
}

/// What an import found.
#[derive(Clone, Debug, PartialEq)]
pub struct CaptureSummary {
    pub width: usize,
    pub height: usize,
    pub saturated: usize,
    /// Pixels left out because their four values give a DoP above 1
    /// (interpolation across edges in a demosaiced frame).
    pub impossible_dop: usize,
    /// Pixels in the mask (all pixels when there is none).
    pub masked: usize,
    /// Whether the labelling of the four images fits the data.
    pub pattern: PatternCheck,
}

/// Largest share of the object whose DoP may exceed 1 before the import is
/// refused: a few edge pixels are interpolation, a large share is a wrong
/// polarizer pattern or order.
const MAX_IMPOSSIBLE_SHARE: f64 = 0.05;

/// Reads an object mask image (`path` named in errors).
pub fn read_mask(path: &Path) -> Result<Mask> {
    io::read_mask_png(path)
}

/// The four polarizer images (0°, 45°, 90°, 135°) of separate files, which
/// must agree in size and bit depth.
pub fn read_four(paths: &[&Path; 4]) -> Result<([Image<u16>; 4], u8)> {
    let mut frames = Vec::with_capacity(4);
    for path in paths {
        frames.push(Frame::read(path)?);
    }
    four(frames.try_into().expect("four frames"))
}

/// The codes of four polarizer frames and their bit depth; errors name the
/// frame that differs from the first in size or bit depth.
pub fn four(frames: [Frame; 4]) -> Result<([Image<u16>; 4], u8)> {
    let reference = &frames[0];
    for frame in &frames[1..] {
        if frame.image.size() != reference.image.size() {
            return Err(Error::file(
                &frame.path,
                format!(
                    "{}×{} image, but {} is {}×{}",
                    frame.image.size().0,
                    frame.image.size().1,
                    reference.path.display(),
                    reference.image.size().0,
                    reference.image.size().1
                ),
            ));
        }
        if frame.bits != reference.bits {
            return Err(Error::file(
                &frame.path,
                format!(
                    "{}-bit image, but {} is {}-bit",
                    frame.bits,
                    reference.path.display(),
                    reference.bits
                ),
            ));
        }
    }
    let bits = reference.bits;
    Ok((frames.map(|f| f.image), bits))
}

/// The saturation code: the largest code of the sensor's depth
/// (`sensor_bits`, when it is lower than the file's `bits`) or the file's.
pub fn full_scale(bits: u8, sensor_bits: Option<u8>) -> Result<u16> {
    let depth = sensor_bits.unwrap_or(bits);
    if !(1..=bits).contains(&depth) {
        return Err(Error::invalid(format!(
            "sensor bit depth {depth}: expected 1 to the file's {bits} bits"
        )));
    }
    Ok(if depth >= 16 {
        u16::MAX
    } else {
        (1u16 << depth) - 1
    })
}

/// The view of four polarizer images stored with `bits`-bit codes, masked
/// as `mask` says (see the module doc for saturation). `sensor_bits` is the
/// sensor's own depth when it is lower than the file's (12-bit data in
/// 16-bit PNGs): it sets the saturation code, and larger codes are an error.
/// The labels are checked against the data ([`pattern_check`]): the sum
/// rule over every unsaturated pixel, the orientation along the outline of
/// an object mask. `meta` is stored with the check's figures (`pattern_check`), the
/// pixels left out (`masked_out`) and an automatic mask's thresholds
/// (`auto_mask`) added.
pub fn view_from_images(
    pol: [Image<u16>; 4],
    bits: u8,
    sensor_bits: Option<u8>,
    mask: &MaskSource,
    meta: Meta,
) -> Result<(View, CaptureSummary)> {
    view_from(ViewInput::grey(pol, bits, None), sensor_bits, mask, meta)
}

/// [`view_from_images`] of four colour polarizer images (R, G, B codes):
/// a colour view, checked and masked on its luminance (conventions.md §5),
/// with a pixel saturated when any channel is.
pub fn view_from_colour(
    rgb: [Image<[u16; 3]>; 4],
    bits: u8,
    sensor_bits: Option<u8>,
    mask: &MaskSource,
    meta: Meta,
) -> Result<(View, CaptureSummary)> {
    let (width, height) = rgb[0].size();
    if rgb.iter().any(|p| p.size() != (width, height)) {
        return Err(Error::invalid("the four polarizer images differ in size"));
    }
    view_from(
        ViewInput::of_colour(rgb, bits, None),
        sensor_bits,
        mask,
        meta,
    )
}

/// The view of `input`'s images (its mask is formed here).
fn view_from(
    input: ViewInput,
    sensor_bits: Option<u8>,
    mask: &MaskSource,
    meta: Meta,
) -> Result<(View, CaptureSummary)> {
    let ViewInput {
        pol, bits, colour, ..
    } = input;
    let (width, height) = pol[0].size();
    if pol.iter().any(|p| p.size() != (width, height)) {
        return Err(Error::invalid("the four polarizer images differ in size"));
    }
    let full = full_scale(bits, sensor_bits)?;
    let codes: Vec<u16> = match &colour {
        Some(rgb) => rgb
            .iter()
            .flat_map(|p| p.data())
            .flatten()
            .copied()
            .collect(),
        None => pol.iter().flat_map(|p| p.data()).copied().collect(),
    };
    let largest = codes.iter().copied().max().unwrap_or(0);
    if largest > full {
        return Err(Error::invalid(format!(
            "code {largest} exceeds the {}-bit sensor's largest code {full}",
            sensor_bits.unwrap_or(bits)
        )));
    }
    let saturated = Image::from_fn(width, height, |x, y| match &colour {
        Some(rgb) => rgb.iter().any(|p| p.get(x, y).iter().any(|&c| c >= full)),
        None => pol.iter().any(|p| *p.get(x, y) >= full),
    });
    let saturated_count = saturated.count();
    let unsaturated = |x: usize, y: usize| !*saturated.get(x, y);
    let mask_source = mask;
    let mut meta = meta;
    let mask = match mask_source {
        MaskSource::All => (saturated_count > 0).then(|| saturated.map(|&s| !s)),
        MaskSource::File(m) => {
            if m.size() != (width, height) {
                // A mask of the raw frame beside a superpixel demosaic.
                let hint = if (m.width() / 2, m.height() / 2) == (width, height) {
                    ": the superpixel demosaic halves the frame, so halve the mask, or \
                     keep the full size with --demosaic bilinear"
                } else {
                    ""
                };
                return Err(Error::invalid(format!(
                    "mask is {}×{} but the polarizer images are {width}×{height}{hint}",
                    m.width(),
                    m.height()
                )));
            }
            Some(Image::from_fn(width, height, |x, y| {
                *m.get(x, y) && unsaturated(x, y)
            }))
        }
        &MaskSource::Window(low, high) => {
            if !(0.0..=1.0).contains(&low) || !(low..=1.0).contains(&high) {
                return Err(Error::invalid(format!(
                    "intensity window {low},{high}: expected 0 ≤ low ≤ high ≤ 1 \
                     (fractions of full scale)"
                )));
            }
            Some(Image::from_fn(width, height, |x, y| {
                let mean = pol.iter().map(|p| f64::from(*p.get(x, y))).sum::<f64>() / 4.0;
                let level = mean / f64::from(full);
                unsaturated(x, y) && (low..=high).contains(&level)
            }))
        }
        MaskSource::Auto => {
            let found = auto_mask(&pol, full);
            meta.extra.insert("auto_mask".into(), found.to_json());
            Some(Image::from_fn(width, height, |x, y| {
                *found.mask.get(x, y) && unsaturated(x, y)
            }))
        }
    };
    // Only an object mask has a silhouette (not the outline of saturated
    // pixels).
    let object = match mask_source {
        MaskSource::All => None,
        _ => mask.as_ref(),
    };
    let unsaturated_pixels = (saturated_count > 0).then(|| saturated.map(|&s| !s));
    let pattern = pattern_check::check(&pol, full, unsaturated_pixels.as_ref(), object);
    // A DoP above 1 is impossible: such pixels (bilinear interpolation
    // across an edge) leave the mask, counted, so the view reads back.
    let k = 1.0 / f64::from(full);
    let impossible = Image::from_fn(width, height, |x, y| {
        let v = |i: usize| f64::from(*pol[i].get(x, y)) * k;
        let st = Stokes::from_four(v(0), v(1), v(2), v(3));
        st.s0 > 0.0 && st.dop_unclamped() > 1.0
    });
    let inside = |x: usize, y: usize| mask.as_ref().is_none_or(|m| *m.get(x, y));
    let impossible_dop = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .filter(|&(x, y)| inside(x, y) && *impossible.get(x, y))
        .count();
    let before = mask.as_ref().map_or(width * height, Image::count);
    if impossible_dop as f64 > MAX_IMPOSSIBLE_SHARE * before as f64 {
        let hint = match pattern.fits.first() {
            Some(&order) if !pattern.labelled_fits() => {
                format!(" The data fit another order: {}.", order.describe())
            }
            _ => String::new(),
        };
        return Err(Error::invalid(format!(
            "DoP exceeds 1 at {impossible_dop} of {before} object pixels: are the polarizer \
             angles (or the mosaic pattern) given in the right order?{hint}"
        )));
    }
    let mask = if impossible_dop > 0 {
        Some(Image::from_fn(width, height, |x, y| {
            inside(x, y) && !*impossible.get(x, y)
        }))
    } else {
        mask
    };
    let masked = mask.as_ref().map_or(width * height, Image::count);
    if masked == 0 {
        let why = match mask_source {
            MaskSource::Auto => "--auto-mask found no object",
            MaskSource::Window(..) => "no pixel lies in the --window",
            MaskSource::File(_) => "the mask image marks no unsaturated pixel",
            MaskSource::All => "every pixel is saturated",
        };
        return Err(Error::invalid(format!(
            "the mask is empty: {why} ({} of {} pixels saturated)",
            saturated_count,
            width * height
        )));
    }
    let summary = CaptureSummary {
        width,
        height,
        saturated: saturated_count,
        impossible_dop,
        masked,
        pattern,
    };
    meta.extra
        .insert("pattern_check".into(), summary.pattern.to_json());
    meta.extra.insert(
        "masked_out".into(),
        serde_json::json!({ "saturated": saturated_count, "dop_above_one": impossible_dop }),
    );
    let view = View {
        input: ViewInput {
            pol,
            bits,
            mask,
            colour,
        },
        gt: None,
        meta: Some(meta),
        problems: Vec::new(),
        source: None,
    };
    Ok((view, summary))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pol(values: [u16; 4]) -> [Image<u16>; 4] {
        values.map(|v| Image::from_fn(4, 3, |x, _| if x == 0 { 255 } else { v }))
    }

    #[test]
    fn saturated_pixels_leave_the_mask() {
        let (view, s) = view_from_images(
            pol([100, 80, 60, 80]),
            8,
            None,
            &MaskSource::All,
            Meta::new("t"),
        )
        .unwrap();
        assert_eq!((s.saturated, s.masked), (3, 9));
        let mask = view.input.mask.unwrap();
        assert!(!*mask.get(0, 1) && *mask.get(1, 1));
        // Nothing saturated at 16 bits: no mask at all.
        let (view, s) = view_from_images(
            pol([100, 80, 60, 80]),
            16,
            None,
            &MaskSource::All,
            Meta::new("t"),
        )
        .unwrap();
        assert_eq!((s.saturated, s.masked, view.input.mask), (0, 12, None));
    }

    #[test]
    fn sensor_depth_below_the_files() {
        // 12-bit codes in a 16-bit file: 4095 is saturated, 4096 impossible.
        let pol12 = [2000, 2000, 2000, 4095]
            .map(|v| Image::from_fn(4, 3, |x, _| if x == 0 { v } else { 7 }));
        let (_, s) = view_from_images(
            pol12.clone(),
            16,
            Some(12),
            &MaskSource::All,
            Meta::new("t"),
        )
        .unwrap();
        assert_eq!(s.saturated, 3);
        let (_, s) = view_from_images(pol12, 16, None, &MaskSource::All, Meta::new("t")).unwrap();
        assert_eq!(s.saturated, 0);
        let over = [4096, 1, 1, 1].map(|v| Image::new(2, 2, v));
        let e = view_from_images(over, 16, Some(12), &MaskSource::All, Meta::new("t")).unwrap_err();
        assert!(e.to_string().contains("4096"), "{e}");
        let bad = [1, 1, 1, 1].map(|v| Image::new(2, 2, v));
        assert!(view_from_images(bad, 8, Some(12), &MaskSource::All, Meta::new("t")).is_err());
    }

    #[test]
    fn window_and_file_masks() {
        let window = MaskSource::Window(0.2, 0.4);
        let (_, s) =
            view_from_images(pol([100, 80, 60, 80]), 8, None, &window, Meta::new("t")).unwrap();
        assert_eq!(s.masked, 9); // mean 80/255 = 0.31
        let dark = MaskSource::Window(0.0, 0.1);
        let e =
            view_from_images(pol([100, 80, 60, 80]), 8, None, &dark, Meta::new("t")).unwrap_err();
        assert!(e.to_string().contains("mask is empty"), "{e}");
        let file = MaskSource::File(Image::from_fn(4, 3, |x, y| x + y < 3));
        let (_, s) =
            view_from_images(pol([100, 80, 60, 80]), 8, None, &file, Meta::new("t")).unwrap();
        assert_eq!(s.masked, 3); // (1,0), (2,0), (1,1); column 0 is saturated
        let wrong = MaskSource::File(Image::new(5, 3, true));
        assert!(view_from_images(pol([1, 1, 1, 1]), 8, None, &wrong, Meta::new("t")).is_err());
        let bad = MaskSource::Window(0.5, 0.2);
        assert!(view_from_images(pol([1, 1, 1, 1]), 8, None, &bad, Meta::new("t")).is_err());
    }
}
