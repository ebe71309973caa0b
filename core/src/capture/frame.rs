//! A frame of sensor codes and where it came from: a raw frame, one of four
//! polarizer images, a dark frame or a flat field, read from a PNG or given
//! as codes in memory. Errors about it name its file (or its array).

use crate::io;
use crate::{Image, Result};
use std::path::{Path, PathBuf};

/// Sensor codes, their file's bit depth and the file they came from (for
/// codes in memory, the name errors and `meta.json` give them).
#[derive(Clone, Debug)]
pub struct Frame {
    pub path: PathBuf,
    /// The codes (of a colour image: the Rec. 709 luminance of its channels).
    pub image: Image<u16>,
    pub bits: u8,
    /// The R, G, B codes of a colour polarizer image.
    pub colour: Option<Image<[u16; 3]>>,
}

impl Frame {
    /// Reads an 8- or 16-bit grayscale PNG.
    pub fn read(path: &Path) -> Result<Frame> {
        let png = io::read_mono_png(path)?;
        let bits = png.bits();
        Ok(Frame {
            path: path.to_path_buf(),
            image: png.into_u16(),
            bits,
            colour: None,
        })
    }

    /// Reads a polarizer image: grey as [`Frame::read`] (an RGB file whose
    /// channels are equal everywhere is grey), or colour (R, G, B codes
    /// kept; a colour view's, conventions.md §5).
    pub fn read_polarizer(path: &Path) -> Result<Frame> {
        let png = io::read_polarizer_png(path)?;
        let bits = png.bits();
        let image = png.luminance();
        let colour = png
            .into_colour()
            .filter(|rgb| rgb.data().iter().any(|p| p[0] != p[1] || p[1] != p[2]));
        Ok(Frame {
            path: path.to_path_buf(),
            image,
            bits,
            colour,
        })
    }
}
