//! Regions of an image: labelled pixel sets with their bounding boxes, and
//! the outer contour of a region. One rule for every client: the solver's
//! connected components (`lsq`), Atkinson's seeding contour, SMSfP's PARG
//! segments and the import's automatic mask are all [`Regions`].
//!
//! Conventions:
//! - connectivity is 8-adjacency (a row of the least-squares system couples a
//!   3×3 neighbourhood, so 8-connected pixels share one height field);
//! - each region's pixels are listed in raster order (row by row from the
//!   top), so unknown numbering and tie-breaking never depend on how a
//!   region was found;
//! - regions are numbered in raster order of their first pixel.
//!
//! The **outer contour** of a region is the set of its pixels 4-adjacent to
//! the region's *outside*: the background connected to infinity when every
//! other label is ignored. A hole (background enclosed by the region) is not
//! outside, so its rim is not on the outer contour: a hole may be a shadow, a
//! specularity or a pit, not an occluding contour. Pixels beyond the image
//! frame are outside but not a contour (the frame cuts the surface); they are
//! used only when a region has no other contour.

use crate::{Image, Mask};
use std::collections::VecDeque;

/// Label of pixels that belong to no region.
pub const OUTSIDE: u32 = u32::MAX;

/// One region: its pixels (raster indices, increasing) and bounding box
/// (inclusive).
#[derive(Clone, Debug)]
pub struct Region {
    pub pixels: Vec<usize>,
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Region {
    /// The bounding box grown by `margin` pixels and clipped to a `w × h`
    /// image: `(x, y, width, height)`.
    pub fn bbox_with_margin(
        &self,
        margin: usize,
        w: usize,
        h: usize,
    ) -> (usize, usize, usize, usize) {
        let x0 = self.x0.saturating_sub(margin);
        let y0 = self.y0.saturating_sub(margin);
        let x1 = (self.x1 + margin).min(w - 1);
        let y1 = (self.y1 + margin).min(h - 1);
        (x0, y0, x1 - x0 + 1, y1 - y0 + 1)
    }
}

/// A labelling of an image into regions.
#[derive(Clone, Debug)]
pub struct Regions {
    /// Region index per pixel, [`OUTSIDE`] elsewhere.
    pub labels: Image<u32>,
    pub list: Vec<Region>,
}

impl Regions {
    /// The 8-connected components of `mask`.
    pub fn components(mask: &Mask) -> Regions {
        let (w, h) = mask.size();
        let mut labels = Image::new(w, h, OUTSIDE);
        let mut count = 0u32;
        let mut stack = Vec::new();
        for start in 0..w * h {
            if !mask.data()[start] || labels.data()[start] != OUTSIDE {
                continue;
            }
            labels.data_mut()[start] = count;
            stack.push(start);
            while let Some(i) = stack.pop() {
                let (x, y) = (i % w, i / w);
                for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                    for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                        let j = ny * w + nx;
                        if mask.data()[j] && labels.data()[j] == OUTSIDE {
                            labels.data_mut()[j] = count;
                            stack.push(j);
                        }
                    }
                }
            }
            count += 1;
        }
        Self::from_labels(labels)
    }

    /// Regions of a labelling with labels `0..n` ([`OUTSIDE`] elsewhere); a
    /// label may hold several components. Labels are kept as given.
    pub fn from_labels(labels: Image<u32>) -> Regions {
        let (w, _) = labels.size();
        let mut list: Vec<Region> = Vec::new();
        for (i, &l) in labels.data().iter().enumerate() {
            if l == OUTSIDE {
                continue;
            }
            let l = l as usize;
            if list.len() <= l {
                list.resize_with(l + 1, || Region {
                    pixels: Vec::new(),
                    x0: usize::MAX,
                    y0: usize::MAX,
                    x1: 0,
                    y1: 0,
                });
            }
            let (x, y) = (i % w, i / w);
            let r = &mut list[l];
            r.pixels.push(i);
            r.x0 = r.x0.min(x);
            r.x1 = r.x1.max(x);
            r.y0 = r.y0.min(y);
            r.y1 = r.y1.max(y);
        }
        Regions { labels, list }
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The mask of region `label`.
    pub fn mask(&self, label: usize) -> Mask {
        self.labels.map(|&l| l == label as u32)
    }

    /// The outer contour of region `label` (module doc) with each pixel's
    /// outward direction `(o_x, o_y)` (camera frame, y up, unit length): the
    /// sum of the offsets to outside pixels within a disc of `radius`.
    pub fn outer_contour(&self, label: usize, radius: usize) -> Contour {
        let labels = &self.labels;
        let region = &self.list[label];
        let label = label as u32;
        let (w, h) = labels.size();
        // Local grid: the bounding box grown by one pixel, so its frame is outside.
        let (gx0, gy0) = (region.x0 as isize - 1, region.y0 as isize - 1);
        let (gw, gh) = (region.x1 - region.x0 + 3, region.y1 - region.y0 + 3);
        let inside = |x: isize, y: isize| {
            x >= 0
                && y >= 0
                && (x as usize) < w
                && (y as usize) < h
                && *labels.get(x as usize, y as usize) == label
        };
        // Flood the region's outside from the grid frame (4-connected).
        let mut outside = vec![false; gw * gh];
        let mut queue = VecDeque::new();
        for gy in 0..gh {
            for gx in 0..gw {
                if gx == 0 || gy == 0 || gx == gw - 1 || gy == gh - 1 {
                    outside[gy * gw + gx] = true;
                    queue.push_back((gx, gy));
                }
            }
        }
        while let Some((gx, gy)) = queue.pop_front() {
            let neighbours = [
                (gx.wrapping_sub(1), gy),
                (gx + 1, gy),
                (gx, gy.wrapping_sub(1)),
                (gx, gy + 1),
            ];
            for (nx, ny) in neighbours {
                if nx < gw
                    && ny < gh
                    && !outside[ny * gw + nx]
                    && !inside(nx as isize + gx0, ny as isize + gy0)
                {
                    outside[ny * gw + nx] = true;
                    queue.push_back((nx, ny));
                }
            }
        }
        // Outside of the region, anywhere in the plane (beyond the grid too).
        let is_outside = |x: isize, y: isize| {
            let (gx, gy) = (x - gx0, y - gy0);
            if gx < 0 || gy < 0 || gx >= gw as isize || gy >= gh as isize {
                return true;
            }
            outside[gy as usize * gw + gx as usize]
        };
        let in_image =
            |x: isize, y: isize| x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h;

        let mut true_contour = Vec::new();
        let mut frame = Vec::new();
        for &i in &region.pixels {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            let mut touches_contour = false;
            let mut touches_frame = false;
            for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                if is_outside(nx, ny) {
                    if in_image(nx, ny) {
                        touches_contour = true;
                    } else {
                        touches_frame = true;
                    }
                }
            }
            if touches_contour {
                true_contour.push(i);
            } else if touches_frame {
                frame.push(i);
            }
        }
        let frame_only = true_contour.is_empty();
        let pixels = if frame_only { frame } else { true_contour };
        let r = radius as isize;
        let seeds = pixels
            .into_iter()
            .filter_map(|i| {
                let (x, y) = ((i % w) as isize, (i / w) as isize);
                let (mut ox, mut oy) = (0.0, 0.0);
                for dy in -r..=r {
                    for dx in -r..=r {
                        if dx * dx + dy * dy <= r * r && is_outside(x + dx, y + dy) {
                            ox += dx as f64;
                            oy -= dy as f64; // rows grow downwards, camera y up
                        }
                    }
                }
                let len = ox.hypot(oy);
                (len > 1e-9).then(|| (i, [ox / len, oy / len]))
            })
            .collect();
        Contour { seeds, frame_only }
    }
}

/// Outer-contour pixels of a region and their outward directions.
#[derive(Clone, Debug)]
pub struct Contour {
    /// `(raster index, [o_x, o_y])`, raster order; pixels whose outward
    /// direction cancels out (a one-pixel-wide line) are left out.
    pub seeds: Vec<(usize, [f64; 2])>,
    /// The pixels lie on the image frame (the region has no contour).
    pub frame_only: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn components_are_8_connected_raster_ordered_with_boxes() {
        // Two diagonal pixels (one component), a separate bar, an island.
        let mask = Mask::from_fn(8, 6, |x, y| {
            (x, y) == (1, 1) || (x, y) == (2, 2) || (x == 5 && y < 4) || (x, y) == (1, 5)
        });
        let r = Regions::components(&mask);
        assert_eq!(r.len(), 3);
        // The bar's first pixel (5, 0) comes first in raster order.
        assert_eq!(r.list[0].pixels, vec![5, 13, 21, 29]);
        assert_eq!(r.list[1].pixels, vec![9, 18]);
        assert_eq!(r.list[2].pixels, vec![41]);
        let b = &r.list[0];
        assert_eq!((b.x0, b.y0, b.x1, b.y1), (5, 0, 5, 3));
        assert_eq!(b.bbox_with_margin(1, 8, 6), (4, 0, 3, 5));
        assert_eq!(*r.labels.get(0, 0), OUTSIDE);
        assert_eq!(r.mask(2).count(), 1);
    }

    #[test]
    fn outer_contour_skips_holes_and_points_outwards() {
        // A 9×9 square with a 3×3 hole in a 13×13 image.
        let mask = Mask::from_fn(13, 13, |x, y| {
            (2..11).contains(&x)
                && (2..11).contains(&y)
                && !((5..8).contains(&x) && (5..8).contains(&y))
        });
        let r = Regions::components(&mask);
        let c = r.outer_contour(0, 3);
        assert!(!c.frame_only);
        // 32 pixels on the square's rim, none on the hole's.
        assert_eq!(c.seeds.len(), 32);
        for &(i, [ox, oy]) in &c.seeds {
            let (x, y) = (i % 13, i / 13);
            assert!(!(4..9).contains(&x) || !(4..9).contains(&y));
            // Outward: towards the nearer side of the square (y up).
            if x == 2 && (4..9).contains(&y) {
                assert!(ox < -0.9, "{ox} {oy}");
            }
            if y == 2 && (4..9).contains(&x) {
                assert!(oy > 0.9, "{ox} {oy}");
            }
        }
    }

    #[test]
    fn frame_filling_region_uses_the_frame() {
        let r = Regions::components(&Mask::new(5, 4, true));
        let c = r.outer_contour(0, 2);
        assert!(c.frame_only);
        assert!(!c.seeds.is_empty());
    }

    #[test]
    fn from_labels_groups_disconnected_pixels() {
        let labels = Image::from_vec(4, 1, vec![1, OUTSIDE, 0, 1]).unwrap();
        let r = Regions::from_labels(labels);
        assert_eq!(r.len(), 2);
        assert_eq!(r.list[1].pixels, vec![0, 3]);
        assert_eq!(r.list[0].pixels, vec![2]);
    }
}
