//! The unknowns of a masked problem: one height per mask pixel, numbered in
//! raster order (row by row from the top, left to right).
//!
//! Raster numbering keeps every finite-difference coupling within a small
//! index band, which the assembly in `lsq` relies on.

use sfp_core::{Image, Mask};

/// Marks a pixel outside the mask in [`Domain`]'s index map.
const OUTSIDE: u32 = u32::MAX;

/// Mask pixels and their unknown indices.
#[derive(Clone, Debug)]
pub struct Domain {
    width: usize,
    height: usize,
    /// Unknown index per pixel, [`OUTSIDE`] outside the mask.
    index: Vec<u32>,
    /// `(x, y)` of each unknown.
    pixels: Vec<(u32, u32)>,
}

impl Domain {
    pub fn new(mask: &Mask) -> Self {
        let (width, height) = mask.size();
        let mut index = vec![OUTSIDE; width * height];
        let mut pixels = Vec::with_capacity(mask.count());
        for y in 0..height {
            for x in 0..width {
                if *mask.get(x, y) {
                    index[y * width + x] = pixels.len() as u32;
                    pixels.push((x as u32, y as u32));
                }
            }
        }
        Domain {
            width,
            height,
            index,
            pixels,
        }
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }

    /// `(width, height)` of the image the domain lives in.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Unknown index of pixel `(x, y)`, `None` outside the image or mask.
    #[inline]
    pub fn at(&self, x: isize, y: isize) -> Option<usize> {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            return None;
        }
        let k = self.index[y as usize * self.width + x as usize];
        (k != OUTSIDE).then_some(k as usize)
    }

    /// Pixel `(x, y)` of unknown `k`.
    #[inline]
    pub fn pixel(&self, k: usize) -> (usize, usize) {
        let (x, y) = self.pixels[k];
        (x as usize, y as usize)
    }

    /// The pixels of the domain as a mask.
    pub fn mask(&self) -> Mask {
        Image::from_vec(
            self.width,
            self.height,
            self.index.iter().map(|&k| k != OUTSIDE).collect(),
        )
        .expect("index map has the image size")
    }

    /// Unknown index of the pixel at raster index `i`, `None` outside.
    #[inline]
    pub fn unknown(&self, i: usize) -> Option<usize> {
        let k = self.index[i];
        (k != OUTSIDE).then_some(k as usize)
    }

    /// Places per-unknown `values` into an image, `outside` elsewhere.
    pub fn scatter<T: Clone>(&self, values: &[T], outside: T) -> Image<T> {
        debug_assert_eq!(values.len(), self.len());
        let mut image = Image::new(self.width, self.height, outside);
        for (k, v) in values.iter().enumerate() {
            let (x, y) = self.pixel(k);
            *image.get_mut(x, y) = v.clone();
        }
        image
    }

    /// Values of `image` at the unknowns, in unknown order.
    pub fn gather<T: Clone>(&self, image: &Image<T>) -> Vec<T> {
        (0..self.len())
            .map(|k| {
                let (x, y) = self.pixel(k);
                image.get(x, y).clone()
            })
            .collect()
    }
}

/// The entries of `values` at the indices `at`, in `at`'s order (a system's
/// unknowns out of a domain-indexed vector, or unknowns out of a grid).
pub fn gather_at<T: Copy>(at: &[usize], values: &[T]) -> Vec<T> {
    at.iter().map(|&i| values[i]).collect()
}

/// Writes `values` (in `at`'s order) at the indices `at` of `to`; the
/// inverse of [`gather_at`].
pub fn scatter_at<T: Copy>(at: &[usize], values: &[T], to: &mut [T]) {
    for (&i, &v) in at.iter().zip(values) {
        to[i] = v;
    }
}
