//! Albedo textures: an image's linear luminance, looked up bilinearly with
//! repeat wrapping. Files are decoded as sRGB (the usual encoding of colour
//! and albedo textures, 8 or 16 bit, gray or RGB(A)) and reduced to Rec. 709
//! luminance, since the renderer is monochrome.

use glam::Vec2;
use sfp_core::{Error, Result};
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<f32>,
}

/// sRGB transfer function → linear.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Texture {
    pub fn load(path: &Path) -> Result<Texture> {
        let img = image::open(path)
            .map_err(|e| Error::file(path, format!("cannot read texture: {e}")))?
            .to_rgb32f();
        let (w, h) = (img.width() as usize, img.height() as usize);
        if w == 0 || h == 0 {
            return Err(Error::file(path, "texture is empty"));
        }
        let texels = img
            .pixels()
            .map(|p| {
                let [r, g, b] = p.0.map(srgb_to_linear);
                0.2126 * r + 0.7152 * g + 0.0722 * b
            })
            .collect();
        Ok(Texture::from_linear(w, h, texels))
    }

    /// From linear values, row-major with row 0 at `v = 0` (top).
    pub fn from_linear(width: usize, height: usize, texels: Vec<f32>) -> Texture {
        debug_assert_eq!(texels.len(), width * height);
        Texture {
            width,
            height,
            texels,
        }
    }

    /// Bilinear lookup at `uv` (origin top-left, repeating).
    #[inline]
    pub fn lookup(&self, uv: Vec2) -> f32 {
        let x = uv.x.rem_euclid(1.0) * self.width as f32 - 0.5;
        let y = uv.y.rem_euclid(1.0) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f32, n: usize| (i as isize).rem_euclid(n as isize) as usize;
        let at =
            |i: f32, j: f32| self.texels[wrap(j, self.height) * self.width + wrap(i, self.width)];
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
        let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_hits_texel_centres_and_wraps() {
        let t = Texture::from_linear(2, 2, vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(t.lookup(Vec2::new(0.25, 0.25)), 0.0);
        assert_eq!(t.lookup(Vec2::new(0.75, 0.75)), 3.0);
        assert_eq!(t.lookup(Vec2::new(1.25, -0.75)), 0.0);
        assert!((t.lookup(Vec2::new(0.5, 0.25)) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn png_is_decoded_as_srgb_luminance() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.png");
        image::GrayImage::from_raw(2, 1, vec![255, 188])
            .unwrap()
            .save(&p)
            .unwrap();
        let t = Texture::load(&p).unwrap();
        assert!((t.texels[0] - 1.0).abs() < 1e-6);
        // sRGB 188/255 ≈ 0.5 linear.
        assert!((t.texels[1] - 0.5029).abs() < 1e-3, "{}", t.texels[1]);
        let err = Texture::load(&dir.path().join("none.png"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("none.png"));
    }
}
