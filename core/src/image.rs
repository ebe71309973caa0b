//! Planar image buffers.
//!
//! Pixel `(x, y)` is column `x`, row `y`; row 0 is the **top** row and data is
//! row-major. The camera frame (conventions.md §1) has `+x` to the right and
//! `+y` **up**, so camera `+y` points towards smaller row indices: any finite
//! difference along rows must flip its sign. Pixel centres sit at `+0.5`.

use crate::{Error, Result};

/// A `width × height` row-major buffer of `T`.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    width: usize,
    height: usize,
    data: Vec<T>,
}

/// Object mask: `true` inside the object.
pub type Mask = Image<bool>;

/// Unit normals `(n_x, n_y, n_z)` in the camera frame; `[0, 0, 0]` means "no normal".
pub type NormalMap = Image<[f32; 3]>;

impl<T: Clone> Image<T> {
    /// An image filled with `value`.
    pub fn new(width: usize, height: usize, value: T) -> Self {
        Image {
            width,
            height,
            data: vec![value; width * height],
        }
    }
}

impl<T> Image<T> {
    /// Wraps row-major `data`; fails when its length is not `width * height`.
    pub fn from_vec(width: usize, height: usize, data: Vec<T>) -> Result<Self> {
        if data.len() != width * height {
            return Err(Error::invalid(format!(
                "image buffer has {} values, expected {width}×{height} = {}",
                data.len(),
                width * height
            )));
        }
        Ok(Image {
            width,
            height,
            data,
        })
    }

    /// Builds an image by evaluating `f(x, y)` at every pixel.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> T) -> Self {
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Image {
            width,
            height,
            data,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Linear index of pixel `(x, y)`.
    #[inline]
    pub fn index(&self, x: usize, y: usize) -> usize {
        debug_assert!(x < self.width && y < self.height);
        y * self.width + x
    }

    #[inline]
    pub fn get(&self, x: usize, y: usize) -> &T {
        &self.data[self.index(x, y)]
    }

    #[inline]
    pub fn get_mut(&mut self, x: usize, y: usize) -> &mut T {
        let i = self.index(x, y);
        &mut self.data[i]
    }

    pub fn data(&self) -> &[T] {
        &self.data
    }

    pub fn data_mut(&mut self) -> &mut [T] {
        &mut self.data
    }

    pub fn into_vec(self) -> Vec<T> {
        self.data
    }

    /// Applies `f` to every pixel value.
    pub fn map<U>(&self, f: impl FnMut(&T) -> U) -> Image<U> {
        Image {
            width: self.width,
            height: self.height,
            data: self.data.iter().map(f).collect(),
        }
    }

    /// The `width × height` window whose top-left pixel is `(x0, y0)`.
    /// Panics when the window leaves the image.
    pub fn crop(&self, x0: usize, y0: usize, width: usize, height: usize) -> Image<T>
    where
        T: Clone,
    {
        assert!(
            x0 + width <= self.width && y0 + height <= self.height,
            "crop window leaves the image"
        );
        let mut data = Vec::with_capacity(width * height);
        for y in y0..y0 + height {
            let row = y * self.width;
            data.extend_from_slice(&self.data[row + x0..row + x0 + width]);
        }
        Image {
            width,
            height,
            data,
        }
    }

    /// Same width and height as `other`.
    pub fn same_size<U>(&self, other: &Image<U>) -> bool {
        self.size() == other.size()
    }
}

impl Mask {
    /// Number of pixels inside the mask.
    pub fn count(&self) -> usize {
        self.data.iter().filter(|&&m| m).count()
    }

    /// The unit outward direction `[x right, y up]` (conventions.md §1) of
    /// the outline pixel `(x, y)`: a pixel of the mask with a 4-neighbour
    /// outside it (beyond the image frame does not count), the direction the
    /// sum of unit offsets to the outside pixels within `radius`. `None` off
    /// the outline, and for a one-pixel gap surrounded symmetrically.
    pub fn outward_direction(&self, x: usize, y: usize, radius: isize) -> Option<[f64; 2]> {
        let (w, h) = self.size();
        let outside = |x: isize, y: isize| {
            x >= 0
                && y >= 0
                && (x as usize) < w
                && (y as usize) < h
                && !*self.get(x as usize, y as usize)
        };
        let (xi, yi) = (x as isize, y as isize);
        if !*self.get(x, y)
            || ![(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(dx, dy)| outside(xi + dx, yi + dy))
        {
            return None;
        }
        let mut dir = [0.0; 2];
        for dy in -radius..=radius {
            for dx in -radius..=radius {
                if outside(xi + dx, yi + dy) {
                    let r = ((dx * dx + dy * dy) as f64).sqrt();
                    dir[0] += dx as f64 / r;
                    dir[1] -= dy as f64 / r;
                }
            }
        }
        let n = dir[0].hypot(dir[1]);
        (n > 1e-9).then(|| [dir[0] / n, dir[1] / n])
    }
}
