//! The measured polarization and a surface at halved resolutions, for
//! the mixed-model fit's coarse-to-fine levels (`fit`).
//!
//! A fit on the full grid moves a surface by a pixel's reach per step: a
//! start whose slopes are off over a whole object takes tens of
//! iterations, each a factorisation of every unknown. At half resolution
//! a step costs about a quarter and reaches twice as far, so the coarse
//! levels do the long moves and the finest one refines.
//!
//! A coarse pixel covers a 2×2 block of the finer grid and is in the mask
//! when any of the block is. Its normalised Stokes vector is the
//! precision-weighted mean of the block's; its weight the root mean square
//! of the block's, so a coarse row counts as much as a fine one (the
//! model error, most of `σ`, does not average out). Its intensity is the
//! mean of the block's usable ones. Heights are in pixels
//! of their level: halving a surface halves its heights, keeping slopes.

use sfp_core::{Image, Mask};

/// Measured `(s1, s2)/s0` and each pixel's weight `1/σ` on one grid.
#[derive(Clone, Debug)]
pub struct Measured {
    pub mask: Mask,
    pub v: Image<[f64; 2]>,
    /// `1/σ`; 0 where the data are unusable.
    pub weight: Image<f64>,
    /// Intensity; NaN where it is unusable for shading (dark, unlit or
    /// saturated).
    pub intensity: Image<f64>,
}

impl Measured {
    /// The grid at half the resolution (sizes rounded up).
    pub fn halved(&self) -> Measured {
        let (w, h) = self.mask.size();
        let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
        let mut mask = Mask::new(cw, ch, false);
        let mut v = Image::new(cw, ch, [0.0; 2]);
        let mut weight = Image::new(cw, ch, 0.0);
        let mut intensity = Image::new(cw, ch, f64::NAN);
        for cy in 0..ch {
            for cx in 0..cw {
                let (mut count, mut precision, mut sum) = (0usize, 0.0, [0.0; 2]);
                let (mut lit, mut brightness) = (0usize, 0.0);
                for (x, y) in block(cx, cy, w, h) {
                    if !*self.mask.get(x, y) {
                        continue;
                    }
                    count += 1;
                    let i = *self.intensity.get(x, y);
                    if i.is_finite() {
                        lit += 1;
                        brightness += i;
                    }
                    let p = self.weight.get(x, y).powi(2);
                    let m = self.v.get(x, y);
                    precision += p;
                    sum = [sum[0] + p * m[0], sum[1] + p * m[1]];
                }
                if count == 0 {
                    continue;
                }
                *mask.get_mut(cx, cy) = true;
                if lit > 0 {
                    *intensity.get_mut(cx, cy) = brightness / lit as f64;
                }
                if precision > 0.0 {
                    *v.get_mut(cx, cy) = [sum[0] / precision, sum[1] / precision];
                    *weight.get_mut(cx, cy) = (precision / count as f64).sqrt();
                }
            }
        }
        Measured {
            mask,
            v,
            weight,
            intensity,
        }
    }
}

/// The fine pixels of coarse pixel `(cx, cy)` inside a `w × h` grid.
fn block(cx: usize, cy: usize, w: usize, h: usize) -> impl Iterator<Item = (usize, usize)> {
    let (x0, y0) = (2 * cx, 2 * cy);
    (y0..(y0 + 2).min(h)).flat_map(move |y| (x0..(x0 + 2).min(w)).map(move |x| (x, y)))
}

/// `height` (NaN where unknown) at half the resolution over `coarse`:
/// each coarse pixel the mean of its block's finite heights, halved.
pub fn halve_heights(height: &Image<f32>, coarse: &Mask) -> Image<f32> {
    let (w, h) = height.size();
    Image::from_fn(coarse.width(), coarse.height(), |cx, cy| {
        if !*coarse.get(cx, cy) {
            return f32::NAN;
        }
        let (count, sum) = block(cx, cy, w, h)
            .map(|(x, y)| *height.get(x, y))
            .filter(|z| z.is_finite())
            .fold((0, 0.0), |(n, s), z| (n + 1, s + z));
        if count == 0 {
            0.0
        } else {
            sum / count as f32 / 2.0
        }
    })
}

/// Coarse heights at twice the resolution over `fine` (a mask whose
/// halving is `coarse`'s mask): bilinear between the coarse pixels in
/// their mask, doubled; NaN outside `fine`.
pub fn double_heights(coarse: &Image<f32>, fine: &Mask) -> Image<f32> {
    let (cw, ch) = coarse.size();
    Image::from_fn(fine.width(), fine.height(), |x, y| {
        if !*fine.get(x, y) {
            return f32::NAN;
        }
        // The fine pixel's centre in coarse pixel coordinates.
        let u = (x as f32 + 0.5) / 2.0 - 0.5;
        let v = (y as f32 + 0.5) / 2.0 - 0.5;
        let (x0, y0) = (u.floor(), v.floor());
        let (mut total, mut sum) = (0.0f32, 0.0f32);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (cx, cy) = (x0 as isize + dx, y0 as isize + dy);
            if cx < 0 || cy < 0 || cx as usize >= cw || cy as usize >= ch {
                continue;
            }
            let z = *coarse.get(cx as usize, cy as usize);
            if !z.is_finite() {
                continue;
            }
            let wx = if dx == 0 { 1.0 - (u - x0) } else { u - x0 };
            let wy = if dy == 0 { 1.0 - (v - y0) } else { v - y0 };
            total += wx * wy;
            sum += wx * wy * z;
        }
        if total > 0.0 {
            2.0 * sum / total
        } else {
            2.0 * *coarse.get(x / 2, y / 2)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_keeps_its_slope_through_both_directions() {
        // z = 0.3 x − 0.2 y over an odd-sized grid with a hole.
        let mask = Mask::from_fn(13, 9, |x, y| !(5..7).contains(&x) || !(3..5).contains(&y));
        let plane = |x: f32, y: f32| 0.3 * x - 0.2 * y;
        let fine = Image::from_fn(13, 9, |x, y| {
            if *mask.get(x, y) {
                plane(x as f32, y as f32)
            } else {
                f32::NAN
            }
        });
        let measured = Measured {
            mask: mask.clone(),
            v: Image::new(13, 9, [0.1, -0.2]),
            weight: Image::new(13, 9, 2.0),
            intensity: Image::from_fn(13, 9, |x, _| if x == 6 { f64::NAN } else { x as f64 }),
        };
        let coarse = measured.halved();
        assert_eq!(coarse.mask.size(), (7, 5));
        assert!(
            coarse.mask.data().iter().all(|&m| m),
            "every block has a mask pixel"
        );
        let halved = halve_heights(&fine, &coarse.mask);
        // Slope per coarse pixel equals the slope per fine pixel.
        let d = halved.get(1, 0) - halved.get(0, 0);
        assert!((d - 0.3).abs() < 1e-5, "coarse slope {d}");
        let back = double_heights(&halved, &mask);
        for y in 1..8 {
            for x in 1..12 {
                if *mask.get(x, y) && *mask.get(x + 1, y) {
                    let d = back.get(x + 1, y) - back.get(x, y);
                    assert!((d - 0.3).abs() < 0.08, "({x}, {y}): slope {d}");
                }
            }
        }
        assert!(back.get(5, 3).is_nan());
        let [a, b] = *coarse.v.get(3, 2);
        assert!((a - 0.1).abs() < 1e-12 && (b + 0.2).abs() < 1e-12);
        assert!((coarse.weight.get(3, 2) - 2.0).abs() < 1e-12);
        // Block x 6–7: only x = 7 is usable for shading.
        assert_eq!(*coarse.intensity.get(3, 0), 7.0);
        assert_eq!(*coarse.intensity.get(1, 0), 2.5);
    }
}
