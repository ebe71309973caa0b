//! The finest level's result on the view's grid. The authors' demo stops
//! its pyramid at every 2nd pixel of its 256² images (a 128² grid); the
//! port stops at about `Yu2017::finest` pixels across in the same way, and
//! each view pixel then takes the bilinear blend of the level samples
//! around it that lie in the level's refined mask (weights renormalised).
//! Heights are scaled by the step, from the level's pixel units to the
//! view's. At step 1 every refined pixel is its own sample.

use super::level::Level;
use super::pyramid;
use sfp_core::{Image, Mask};

/// The view-grid result of one level.
pub struct OnView {
    pub normals: Image<[f32; 3]>,
    /// Heights in view pixels, NaN where `covered` is false.
    pub heights: Image<f64>,
    /// Pixels of the view's mask with a level sample around them.
    pub covered: Mask,
}

/// Normals and heights `z` of `level` on the pixels of `view_mask` (the
/// view's grid).
pub fn on_view(level: &Level, z: &[f64], view_mask: &Mask) -> OnView {
    let (w, h) = view_mask.size();
    let step = level.step;
    let normals = pyramid::normals(level, z);
    let heights = level.domain.scatter(z, f64::NAN);
    let mask = level.domain.mask();
    let (lw, lh) = mask.size();
    let mut out = OnView {
        normals: Image::new(w, h, [0.0; 3]),
        heights: Image::new(w, h, f64::NAN),
        covered: Mask::new(w, h, false),
    };
    for y in 0..h {
        for x in (0..w).filter(|&x| *view_mask.get(x, y)) {
            let (x0, y0) = (x / step, y / step);
            let (tx, ty) = ((x % step) as f64 / step as f64, (y % step) as f64 / step as f64);
            let mut sum = [0.0f64; 5];
            for (sx, sy, weight) in [
                (x0, y0, (1.0 - tx) * (1.0 - ty)),
                (x0 + 1, y0, tx * (1.0 - ty)),
                (x0, y0 + 1, (1.0 - tx) * ty),
                (x0 + 1, y0 + 1, tx * ty),
            ] {
                if weight > 0.0 && sx < lw && sy < lh && *mask.get(sx, sy) {
                    let n = normals.get(sx, sy);
                    let values = [n[0], n[1], n[2]].map(f64::from);
                    (0..3).for_each(|i| sum[i] += weight * values[i]);
                    sum[3] += weight * heights.get(sx, sy) * step as f64;
                    sum[4] += weight;
                }
            }
            let norm = (sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]).sqrt();
            if sum[4] > 0.0 && norm > 0.0 {
                *out.normals.get_mut(x, y) = [0, 1, 2].map(|i| (sum[i] / norm) as f32);
                *out.heights.get_mut(x, y) = sum[3] / sum[4];
                *out.covered.get_mut(x, y) = true;
            }
        }
    }
    out
}
