//! Guided image filter (He, Sun, Tang: "Guided Image Filtering", ECCV 2010 /
//! TPAMI 2013), restricted to a mask.
//!
//! SMSfP reconstructs each polarization region on its own and stitches the
//! normals; across a stitching seam the normals jump. Smoothing them with the
//! unpolarized intensity `I_un` as guide removes the seam where the image is
//! smooth but keeps real creases, which show up as edges in `I_un`.
//!
//! The filter assumes the output is locally a linear function of the guide:
//! in every window `ω_k` of `(2r+1)²` pixels, `q_i = a_k I_i + b_k` with
//! (TPAMI 2013, Eqs. 5–6)
//!
//! ```text
//! a_k = cov_k(I, p) / (var_k(I) + ε),   b_k = mean_k(p) − a_k mean_k(I),
//! ```
//!
//! and every pixel averages the models of the windows that contain it
//! (Eq. 8): `q_i = mean_{k ∈ ω_i}(a_k) I_i + mean_{k ∈ ω_i}(b_k)`. Where the
//! guide is flat (`var ≪ ε`) `a ≈ 0` and the output is a smoothed `p`; at a
//! guide edge (`var ≫ ε`) `a ≈ cov/var` and the output follows the edge.
//!
//! Choices the paper leaves open (it filters whole rectangular images), made
//! here:
//! - **masking**: every mean is taken over the mask pixels of the window
//!   (divided by their count, not by `(2r+1)²`); pixels outside the mask
//!   neither contribute nor change, and only windows centred on mask pixels
//!   carry a linear model. Windows are clipped at the image border the same
//!   way;
//! - with a constant guide the filter is therefore the masked box mean
//!   **applied twice** (`a_k = 0`, `b_k` = mean of `p` over `ω_k`, then the
//!   mean of the `b_k`), not a single box mean;
//! - `ε = 0` is allowed; a window whose guide is then exactly flat gets
//!   `a_k = 0` (its output is the mean of `p`) instead of `0/0`;
//! - box sums come from summed-area tables in `f64` (O(1) per pixel and
//!   window, whatever the radius), over guide and source values minus their
//!   masked means so that `E[I²] − E[I]²` does not cancel catastrophically
//!   for guides with a large offset (raw sensor counts);
//! - the normals filter treats `n_x`, `n_y`, `n_z` as three sources with the
//!   same guide and renormalises. The guided filter is not a convex
//!   combination (`a` may exceed 1 near edges), so a filtered vector that
//!   vanishes keeps its input value.

use crate::solver::ordered_sum::ordered_sum;
use rayon::prelude::*;
use sfp_core::integral::Integral;
use sfp_core::{Image, Mask};

/// Guided filter of `src` with guide `guide`, over `mask` only (pixels outside
/// neither contribute nor change), radius `radius` (box `(2r+1)²`), regulariser
/// `eps` (in guide units squared, ≥ 0).
///
/// Panics when the three images differ in size or `eps` is negative or not
/// finite.
pub fn guided_filter(
    guide: &Image<f32>,
    src: &Image<f32>,
    mask: &Mask,
    radius: usize,
    eps: f64,
) -> Image<f32> {
    assert!(guide.same_size(src), "guide and source differ in size");
    let g = Guide::new(guide, mask, radius, eps);
    let q = g.filter(|i| f64::from(src.data()[i]));
    let mut out = src.clone();
    for ((o, &v), &m) in out.data_mut().iter_mut().zip(&q).zip(mask.data()) {
        if m {
            *o = v as f32;
        }
    }
    out
}

/// Filters each normal component with the same guide and renormalises.
/// Pixels outside the mask keep their value (`[0, 0, 0]` by convention) and
/// do not contribute; mask pixels where `only` is false (e.g. away from a band
/// around region boundaries) keep their value bit for bit but still
/// contribute to their neighbours. `only = None` changes every mask pixel.
///
/// Panics when the images differ in size or `eps` is negative or not finite.
pub fn filter_normals(
    guide: &Image<f32>,
    normals: &Image<[f32; 3]>,
    mask: &Mask,
    only: Option<&Mask>,
    radius: usize,
    eps: f64,
) -> Image<[f32; 3]> {
    assert!(guide.same_size(normals), "guide and normals differ in size");
    if let Some(only) = only {
        assert!(only.same_size(mask), "`only` and mask differ in size");
    }
    let g = Guide::new(guide, mask, radius, eps);
    let q: Vec<Vec<f64>> = (0..3)
        .map(|c| g.filter(|i| f64::from(normals.data()[i][c])))
        .collect();
    let mut out = normals.clone();
    out.data_mut()
        .par_iter_mut()
        .enumerate()
        .filter(|&(i, _)| mask.data()[i] && only.is_none_or(|o| o.data()[i]))
        .for_each(|(i, n)| {
            let v = [q[0][i], q[1][i], q[2][i]];
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if len > 1e-12 && len.is_finite() {
                *n = v.map(|c| (c / len) as f32);
            }
        });
    out
}

/// A guide restricted to a mask, with its window statistics: everything the
/// filter needs that does not depend on the source, shared by the channels
/// filtered with it.
struct Guide<'a> {
    mask: &'a Mask,
    /// Guide minus its masked mean; 0 outside the mask.
    values: Vec<f64>,
    /// Per window: mask pixel count, `Σ g`, `Σ g²`.
    stats: Integral<3>,
    radius: usize,
    eps: f64,
}

impl<'a> Guide<'a> {
    fn new(guide: &Image<f32>, mask: &'a Mask, radius: usize, eps: f64) -> Self {
        assert!(guide.same_size(mask), "guide and mask differ in size");
        assert!(
            eps >= 0.0 && eps.is_finite(),
            "eps must be finite and ≥ 0, got {eps}"
        );
        let (w, h) = guide.size();
        let mean = masked_mean(mask, |i| f64::from(guide.data()[i]));
        let values: Vec<f64> = guide
            .data()
            .par_iter()
            .zip(mask.data())
            .map(|(&g, &m)| if m { f64::from(g) - mean } else { 0.0 })
            .collect();
        let stats = Integral::new(w, h, |i| {
            let g = values[i];
            [f64::from(u8::from(mask.data()[i])), g, g * g]
        });
        Guide {
            mask,
            values,
            stats,
            radius,
            eps,
        }
    }

    /// The filtered source at every mask pixel (0 outside).
    fn filter(&self, src: impl Fn(usize) -> f64 + Sync) -> Vec<f64> {
        let (w, h) = self.mask.size();
        let mask = self.mask.data();
        let offset = masked_mean(self.mask, &src);
        let p = |i: usize| if mask[i] { src(i) - offset } else { 0.0 };
        let cross = Integral::new(w, h, |i| {
            let v = p(i);
            [v, self.values[i] * v]
        });
        // Linear model (a_k, b_k) of every window centred on a mask pixel.
        let mut ab = vec![[0.0f64; 2]; w * h];
        ab.par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                for (x, out) in row.iter_mut().enumerate() {
                    if !mask[y * w + x] {
                        continue;
                    }
                    let [n, sg, sgg] = self.stats.window(x, y, self.radius);
                    let [sp, sgp] = cross.window(x, y, self.radius);
                    let (mg, mp) = (sg / n, sp / n);
                    let var = (sgg / n - mg * mg).max(0.0);
                    let cov = sgp / n - mg * mp;
                    let den = var + self.eps;
                    let a = if den > 0.0 { cov / den } else { 0.0 };
                    *out = [a, mp - a * mg];
                }
            });
        let models = Integral::new(w, h, |i| ab[i]);
        let mut q = vec![0.0f64; w * h];
        q.par_chunks_mut(w.max(1)).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let i = y * w + x;
                if mask[i] {
                    let [n, _, _] = self.stats.window(x, y, self.radius);
                    let [sa, sb] = models.window(x, y, self.radius);
                    *out = (sa * self.values[i] + sb) / n + offset;
                }
            }
        });
        q
    }
}

/// Mean of `value` over the mask (0 for an empty mask), in a fixed order
/// of additions (`ordered_sum`): a rayon reduction's order follows the
/// work stealing, and its last bits moved the stitched height, and the
/// mixed-model fit started from it, between runs on the same view.
fn masked_mean(mask: &Mask, value: impl Fn(usize) -> f64 + Sync) -> f64 {
    let inside = mask.data();
    let n = inside.iter().filter(|&&m| m).count();
    let sum = ordered_sum(inside.len(), |i| if inside[i] { value(i) } else { 0.0 });
    if n > 0 { sum / n as f64 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    /// A disc with a square hole and a few stray pixels: borders, holes and
    /// partially covered windows everywhere.
    fn awkward_mask(n: usize) -> Mask {
        let c = n as f64 / 2.0;
        Mask::from_fn(n, n, |x, y| {
            let (dx, dy) = (x as f64 + 0.5 - c, y as f64 + 0.5 - c);
            let disc = dx * dx + dy * dy < (0.45 * n as f64).powi(2);
            let hole = dx.abs() < 3.0 && dy.abs() < 2.0;
            (disc && !hole) || (x + 2 * y) % 17 == 0
        })
    }

    fn noise(n: usize, seed: u64, amp: f64) -> Image<f32> {
        let mut rng = Pcg64::seed_from_u64(seed);
        Image::from_fn(n, n, |_, _| (amp * (rng.random::<f64>() - 0.5)) as f32)
    }

    /// Masked box mean by brute force (image-clipped window).
    fn box_mean(src: &Image<f64>, mask: &Mask, r: usize) -> Image<f64> {
        let (w, h) = src.size();
        Image::from_fn(w, h, |x, y| {
            let (mut s, mut n) = (0.0, 0.0);
            for yy in y.saturating_sub(r)..(y + r + 1).min(h) {
                for xx in x.saturating_sub(r)..(x + r + 1).min(w) {
                    if *mask.get(xx, yy) {
                        s += src.get(xx, yy);
                        n += 1.0;
                    }
                }
            }
            if n > 0.0 { s / n } else { 0.0 }
        })
    }

    #[test]
    fn the_masked_mean_adds_in_the_same_order_on_every_run() {
        use crate::solver::ordered_sum::CHUNK;
        // Terms whose sum depends on the order of the additions, over more
        // pixels than one chunk, so threads share the work.
        let n = 600;
        let mask = awkward_mask(n);
        let values = noise(n, 5, 2.0);
        let term = |i: usize| f64::from(values.data()[i]) * 10f64.powi((i % 17) as i32);
        let inside = |i: usize| if mask.data()[i] { term(i) } else { 0.0 };
        let count = mask.data().iter().filter(|&&m| m).count() as f64;
        // Chunk by chunk in raster order, then the chunks in order.
        let expected = (0..(n * n).div_ceil(CHUNK))
            .map(|c| {
                (c * CHUNK..((c + 1) * CHUNK).min(n * n))
                    .map(inside)
                    .sum::<f64>()
            })
            .sum::<f64>()
            / count;
        for _ in 0..20 {
            assert_eq!(masked_mean(&mask, term).to_bits(), expected.to_bits());
        }
    }

    #[test]
    fn constant_guide_is_the_masked_box_mean_applied_twice() {
        let n = 40;
        let mask = awkward_mask(n);
        let src = noise(n, 1, 2.0).map(|&v| v + 3.0);
        let guide = Image::new(n, n, 0.7f32);
        for r in [0, 1, 3, 6] {
            let out = guided_filter(&guide, &src, &mask, r, 1e-3);
            let once = box_mean(&src.map(|&v| f64::from(v)), &mask, r);
            let twice = box_mean(&once, &mask, r);
            for y in 0..n {
                for x in 0..n {
                    let want = if *mask.get(x, y) {
                        *twice.get(x, y)
                    } else {
                        f64::from(*src.get(x, y))
                    };
                    let got = f64::from(*out.get(x, y));
                    assert!(
                        (got - want).abs() < 1e-5,
                        "r {r} ({x}, {y}): {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn source_equal_to_guide_passes_through() {
        let n = 48;
        let mask = awkward_mask(n);
        // A textured guide with a large offset (raw-count-like values).
        let guide = Image::from_fn(n, n, |x, y| {
            (1000.0 + 50.0 * (0.3 * x as f64).sin() * (0.2 * y as f64).cos()) as f32
        });
        let out = guided_filter(&guide, &guide, &mask, 4, 1e-6);
        let worst = out
            .data()
            .iter()
            .zip(guide.data())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-2, "worst deviation {worst} on values ≈ 1000");
    }

    #[test]
    fn step_edge_survives_while_noise_drops() {
        let (n, edge, r) = (64usize, 32usize, 4usize);
        let mask = Mask::new(n, n, true);
        let step = |x: usize| if x < edge { 0.0f32 } else { 1.0 };
        let guide = Image::from_fn(n, n, |x, _| step(x));
        let sigma = 0.1f64;
        let mut rng = Pcg64::seed_from_u64(7);
        let src = Image::from_fn(n, n, |x, _| {
            step(x) + (sigma * 12f64.sqrt() * (rng.random::<f64>() - 0.5)) as f32
        });
        let out = guided_filter(&guide, &src, &mask, r, 1e-2);
        // Column means: still a step, sharp to within one pixel of the edge
        // (measured: off by ≤ 0.022 on the two edge columns, ≤ 0.015 elsewhere).
        let col_mean = |img: &Image<f32>, x: usize| {
            (0..n).map(|y| f64::from(*img.get(x, y))).sum::<f64>() / n as f64
        };
        for x in 0..n {
            let m = col_mean(&out, x);
            let want = f64::from(step(x));
            let tol = if x + 1 == edge || x == edge {
                0.05
            } else {
                0.02
            };
            assert!((m - want).abs() < tol, "column {x}: mean {m}");
        }
        // Noise: the variance about the clean step drops on both sides,
        // including the columns whose windows straddle the edge (measured:
        // by 40× next to the edge, 200× away from it).
        let var = |img: &Image<f32>, cols: std::ops::Range<usize>| {
            let k = cols.len() * n;
            cols.flat_map(|x| (0..n).map(move |y| (x, y)))
                .map(|(x, y)| (f64::from(*img.get(x, y)) - f64::from(step(x))).powi(2))
                .sum::<f64>()
                / k as f64
        };
        for cols in [0..edge - r, edge - r..edge, edge..edge + r, edge + r..n] {
            let (before, after) = (var(&src, cols.clone()), var(&out, cols.clone()));
            assert!(
                after < 0.05 * before,
                "columns {cols:?}: variance {before} → {after}"
            );
        }
    }

    #[test]
    fn pixels_outside_the_mask_neither_contribute_nor_change() {
        let n = 32;
        let mask = awkward_mask(n);
        let guide = noise(n, 3, 1.0);
        let src = noise(n, 4, 1.0);
        let poisoned = Image::from_fn(
            n,
            n,
            |x, y| {
                if *mask.get(x, y) { *src.get(x, y) } else { 1e6 }
            },
        );
        let wild_guide = Image::from_fn(n, n, |x, y| {
            if *mask.get(x, y) {
                *guide.get(x, y)
            } else {
                -1e5
            }
        });
        let a = guided_filter(&guide, &src, &mask, 3, 1e-2);
        let b = guided_filter(&wild_guide, &poisoned, &mask, 3, 1e-2);
        for i in 0..n * n {
            if mask.data()[i] {
                assert!((a.data()[i] - b.data()[i]).abs() < 1e-5, "pixel {i}");
            } else {
                assert_eq!(a.data()[i], src.data()[i]);
                assert_eq!(b.data()[i], 1e6);
            }
        }
    }

    #[test]
    fn normals_stay_unit_and_untouched_outside_the_band() {
        let n = 48;
        let mask = awkward_mask(n);
        let guide = noise(n, 5, 0.2).map(|&v| v + 0.5);
        let mut rng = Pcg64::seed_from_u64(6);
        let normals = Image::from_fn(n, n, |x, y| {
            if !*mask.get(x, y) {
                return [0.0; 3];
            }
            // A seam at x = n/2: two tilts, plus noise.
            let tilt = if x < n / 2 { 0.3 } else { -0.2 };
            let v = [
                tilt + 0.05 * (rng.random::<f64>() - 0.5),
                0.1 + 0.05 * (rng.random::<f64>() - 0.5),
                1.0,
            ];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| (c / l) as f32)
        });
        let band = Mask::from_fn(n, n, |x, _| x.abs_diff(n / 2) <= 3);
        let out = filter_normals(&guide, &normals, &mask, Some(&band), 3, 1e-2);
        let mut changed = 0;
        for y in 0..n {
            for x in 0..n {
                let (a, b) = (*out.get(x, y), *normals.get(x, y));
                if *mask.get(x, y) && *band.get(x, y) {
                    let l = a.iter().map(|c| c * c).sum::<f32>().sqrt();
                    assert!((l - 1.0).abs() < 1e-5, "({x}, {y}) length {l}");
                    changed += usize::from(a != b);
                } else {
                    assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "({x}, {y})");
                }
            }
        }
        assert!(changed > 0);
        // Without a band every mask pixel is filtered and still unit.
        let all = filter_normals(&guide, &normals, &mask, None, 3, 1e-2);
        for (i, v) in all.data().iter().enumerate() {
            let l = v.iter().map(|c| c * c).sum::<f32>().sqrt();
            if mask.data()[i] {
                assert!((l - 1.0).abs() < 1e-5);
            } else {
                assert_eq!(l, 0.0);
            }
        }
    }

    /// Speed at 512² and 1024² (run with `--release -- --ignored --nocapture`).
    #[test]
    #[ignore = "a timing at 512² or more printing seconds (slow in CI); run with --ignored --nocapture"]
    fn timing() {
        for n in [512, 1024] {
            let mask = awkward_mask(n);
            let guide = noise(n, 8, 1.0);
            let src = noise(n, 9, 1.0);
            let normals = Image::new(n, n, [0.0f32, 0.0, 1.0]);
            let t = std::time::Instant::now();
            let out = guided_filter(&guide, &src, &mask, 8, 1e-3);
            let scalar = t.elapsed();
            let t = std::time::Instant::now();
            let nm = filter_normals(&guide, &normals, &mask, None, 8, 1e-3);
            let vector = t.elapsed();
            assert!(out.data().iter().all(|v| v.is_finite()) && nm.len() == n * n);
            println!(
                "{n}²: guided_filter {:.1} ms, filter_normals {:.1} ms (r = 8, {} threads)",
                scalar.as_secs_f64() * 1e3,
                vector.as_secs_f64() * 1e3,
                rayon::current_num_threads()
            );
        }
    }
}
