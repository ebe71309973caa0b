//! Dark frame and flat field of a capture: the sensor's offset without
//! light is subtracted, and its pixel-to-pixel response (vignetting, and in
//! a mosaic the micro-polarizers' different transmission) divided out, so
//! the four polarizer values of a pixel compare like with like.
//!
//! Both frames are raw frames of the same sensor, size and bit depth as
//! the capture (the mosaic itself, or each of four polarizer images). The
//! flat field is a uniformly lit, unpolarized scene; its dark-subtracted
//! values are normalized by their mean, so the correction keeps the
//! capture's scale: `v' = (v − dark) · mean(flat − dark) / (flat − dark)`.
//! A saturated code stays at full scale (the import leaves it out).

use crate::capture::frame::Frame;
use crate::{Error, Image, Result};
use rayon::prelude::*;

/// Fails, naming `frame`'s file, unless it matches the capture.
fn check(frame: &Frame, what: &str, size: (usize, usize), bits: u8) -> Result<()> {
    if frame.image.size() != size {
        let (w, h) = frame.image.size();
        return Err(Error::file(
            &frame.path,
            format!(
                "{what} is {w}×{h}, but the capture is {}×{}",
                size.0, size.1
            ),
        ));
    }
    if frame.bits != bits {
        return Err(Error::file(
            &frame.path,
            format!(
                "{what} is {}-bit, but the capture is {bits}-bit",
                frame.bits
            ),
        ));
    }
    Ok(())
}

/// `image` (`bits`-bit file, saturated at `full`) with `dark` subtracted and
/// `flat` divided out (module doc). Errors name the frame that does not fit.
pub fn correct(
    image: &Image<u16>,
    bits: u8,
    full: u16,
    dark: Option<&Frame>,
    flat: Option<&Frame>,
) -> Result<Image<u16>> {
    let size = image.size();
    // Checked before the correction, which clips to `full` (a 16-bit code in
    // a capture said to be 12-bit passed as saturated).
    if let Some(&code) = image.data().iter().find(|&&v| v > full) {
        return Err(Error::invalid(format!(
            "code {code} exceeds the sensor's largest code {full} (--sensor-bits)"
        )));
    }
    if let Some(d) = dark {
        check(d, "the dark frame", size, bits)?;
    }
    let offset = |i: usize| dark.map_or(0.0, |d| f64::from(d.image.data()[i]));
    let gain = match flat {
        Some(f) => {
            check(f, "the flat field", size, bits)?;
            let signal: Vec<f64> = (0..f.image.len())
                .map(|i| f64::from(f.image.data()[i]) - offset(i))
                .collect();
            let dead = signal.iter().filter(|&&s| s <= 0.0).count();
            if dead > 0 {
                return Err(Error::file(
                    &f.path,
                    format!(
                        "{dead} pixels of the flat field are at or below the dark level: \
                         a flat field is a uniformly lit frame"
                    ),
                ));
            }
            let mean = signal.iter().sum::<f64>() / signal.len() as f64;
            Some(signal.into_iter().map(|s| s / mean).collect::<Vec<_>>())
        }
        None => None,
    };
    let data = image
        .data()
        .par_iter()
        .enumerate()
        .map(|(i, &v)| {
            if v >= full {
                return full;
            }
            let g = gain.as_ref().map_or(1.0, |g| g[i]);
            ((f64::from(v) - offset(i)) / g)
                .round()
                .clamp(0.0, f64::from(full)) as u16
        })
        .collect();
    Image::from_vec(size.0, size.1, data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn frame(name: &str, image: Image<u16>, bits: u8) -> Frame {
        Frame {
            colour: None,
            path: PathBuf::from(name),
            image,
            bits,
        }
    }

    /// A scene `s(x)` seen through a response `g(x)` over an offset `d(x)`
    /// gives `d + g·s`; dark and flat frames of the same sensor give back
    /// `s` scaled by the mean response, to the rounding of one code.
    #[test]
    fn dark_and_flat_undo_offset_and_response() {
        let (w, h) = (16, 8);
        let d = |x: usize, y: usize| 20.0 + ((x * 7 + y * 3) % 5) as f64;
        let g = |x: usize, y: usize| 0.8 + 0.4 * ((x + 2 * y) % 3) as f64 / 2.0;
        let s = |x: usize, y: usize| 100.0 + 50.0 * x as f64 + 30.0 * y as f64;
        let code = |v: f64| v.round() as u16;
        let raw = Image::from_fn(w, h, |x, y| code(d(x, y) + g(x, y) * s(x, y)));
        let dark = frame("dark.png", Image::from_fn(w, h, |x, y| code(d(x, y))), 16);
        let flat = frame(
            "flat.png",
            Image::from_fn(w, h, |x, y| code(d(x, y) + g(x, y) * 30000.0)),
            16,
        );
        let mean_g = (0..h)
            .flat_map(|y| (0..w).map(move |x| g(x, y)))
            .sum::<f64>()
            / (w * h) as f64;
        let out = correct(&raw, 16, u16::MAX, Some(&dark), Some(&flat)).unwrap();
        for y in 0..h {
            for x in 0..w {
                let want = s(x, y) * mean_g;
                let got = f64::from(*out.get(x, y));
                assert!((got - want).abs() <= 1.5, "{x},{y}: {got} vs {want}");
            }
        }
        // Dark only: the offset goes, the response stays.
        let out = correct(&raw, 16, u16::MAX, Some(&dark), None).unwrap();
        assert_eq!(
            *out.get(3, 2),
            code(d(3, 2) + g(3, 2) * s(3, 2)) - code(d(3, 2))
        );
        // A saturated code stays saturated; nothing goes below 0.
        let hot = Image::from_fn(w, h, |x, _| if x == 0 { 255 } else { 1 });
        let dark8 = frame("dark8.png", Image::new(w, h, 10), 8);
        let out = correct(&hot, 8, 255, Some(&dark8), None).unwrap();
        assert_eq!((*out.get(0, 0), *out.get(1, 0)), (255, 0));
    }

    #[test]
    fn frames_that_do_not_fit_are_named() {
        let raw = Image::new(4, 4, 100u16);
        let small = frame("small_dark.png", Image::new(4, 3, 1), 16);
        let e = correct(&raw, 16, u16::MAX, Some(&small), None).unwrap_err();
        assert!(
            e.to_string().contains("small_dark.png") && e.to_string().contains("4×3"),
            "{e}"
        );
        let eight = frame("dark8.png", Image::new(4, 4, 1), 8);
        let e = correct(&raw, 16, u16::MAX, Some(&eight), None).unwrap_err();
        assert!(
            e.to_string().contains("dark8.png: the dark frame is 8-bit"),
            "{e}"
        );
        let black = frame("flat.png", Image::from_fn(4, 4, |x, _| x as u16 * 100), 16);
        let e = correct(&raw, 16, u16::MAX, None, Some(&black)).unwrap_err();
        assert!(e.to_string().contains("flat.png: 4 pixels"), "{e}");
    }
}
