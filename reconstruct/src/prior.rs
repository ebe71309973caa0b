//! Boundary convexity prior (Smith et al. 2016/2019; SMSfP paper §4.3 calls
//! its azimuths the implicit azimuth angles `φ_im`).
//!
//! On the occluding contour of a convex object the normal lies in the image
//! plane and points outwards, perpendicular to the contour. The prior takes
//! that outward direction on the mask's boundary, gives every mask pixel the
//! direction of its closest boundary pixel, smooths the direction field, and
//! weights each pixel by `(1 − d/d_max)^exponent` (`d` = distance to the
//! boundary, `d_max` its largest value over the mask): 1 on the boundary,
//! decaying fast towards the interior, where convexity says little.
//!
//! Choices the papers leave open, made here:
//! - boundary pixels are mask pixels with a 4-neighbour **inside the image**
//!   and outside the mask: where the frame cuts the object there is no
//!   contour, so no prior (a mask filling the frame gets weight 0 everywhere);
//!   holes count as boundary, with the direction pointing into the hole;
//! - the outward direction at a boundary pixel is the mean direction towards
//!   the non-mask pixels of its 5×5 window;
//! - closest boundary pixels come from an exact-in-practice two-pass vector
//!   distance transform (8SSEDT); the field is smoothed by two passes of a
//!   masked 5×5 box filter on the unit vectors.

use crate::solver::domain::Domain;
use rayon::prelude::*;
use sfp_core::{Image, Mask};

/// Default exponent of the distance weight (Smith et al.).
pub const DEFAULT_EXPONENT: f64 = 5.0;

/// Prior azimuth and weight per pixel.
#[derive(Clone, Debug)]
pub struct ConvexityPrior {
    /// Outward azimuth `φ_prior` (camera frame, radians); 0 outside the mask.
    pub azimuth: Image<f32>,
    /// Weight in `[0, 1]`; 0 outside the mask or without any boundary.
    pub weight: Image<f32>,
    /// Distance to the closest boundary pixel (pixels); 0 on the boundary.
    pub distance: Image<f32>,
    /// Share of the mask's boundary pixels that seed the prior (trusted):
    /// how much of the outline the prior holds, 0 to 1.
    pub contour_share: f64,
}

impl ConvexityPrior {
    /// The largest distance from the boundary: the inscribed radius.
    pub fn deepest(&self) -> f32 {
        self.distance.data().iter().copied().fold(0.0, f32::max)
    }
}

/// Half-width of the window that estimates the outward direction.
const NORMAL_RADIUS: isize = 2;
/// Half-width of the smoothing box filter, and how often it is applied.
const SMOOTH_RADIUS: isize = 2;
const SMOOTH_PASSES: usize = 2;

/// The prior of `mask` with distance weights `(1 − d/d_max)^exponent`.
pub fn convexity_prior(mask: &Mask, exponent: f64) -> ConvexityPrior {
    convexity_prior_trusted(mask, exponent, |_, _, _| true)
}

/// As [`convexity_prior`], with only the boundary pixels `(x, y)` whose
/// outward direction `[o_x, o_y]` (camera frame) `trusted` accepts as
/// seeds: where a region's boundary is not an occluding contour the surface
/// continues past it, so it says nothing about the normal (SMSfP's regions).
/// Distances and weights are then measured to the trusted boundary only; a
/// region without any has weight 0 everywhere.
pub fn convexity_prior_trusted(
    mask: &Mask,
    exponent: f64,
    trusted: impl Fn(usize, usize, [f64; 2]) -> bool,
) -> ConvexityPrior {
    let (w, h) = mask.size();
    let domain = Domain::new(mask);
    // Boundary pixels and their outward directions (x right, y up).
    let mut seeds: Vec<(usize, usize, [f64; 2])> = Vec::new();
    let mut outline = 0usize;
    for k in 0..domain.len() {
        let (x, y) = domain.pixel(k);
        if let Some(outward) = mask.outward_direction(x, y, NORMAL_RADIUS) {
            outline += 1;
            if trusted(x, y, outward) {
                seeds.push((x, y, outward));
            }
        }
    }
    let contour_share = if outline > 0 {
        seeds.len() as f64 / outline as f64
    } else {
        0.0
    };
    let mut azimuth = Image::new(w, h, 0.0f32);
    let mut weight = Image::new(w, h, 0.0f32);
    let mut distance = Image::new(w, h, 0.0f32);
    if seeds.is_empty() {
        return ConvexityPrior {
            azimuth,
            weight,
            distance,
            contour_share,
        };
    }
    let nearest = nearest_seed(w, h, &seeds);
    let mut field = Image::new(w, h, [0.0f64; 2]);
    let mut d_max: f64 = 0.0;
    for k in 0..domain.len() {
        let (x, y) = domain.pixel(k);
        let s = nearest[y * w + x];
        let (sx, sy, dir) = seeds[s];
        let d = ((x as f64 - sx as f64).powi(2) + (y as f64 - sy as f64).powi(2)).sqrt();
        *distance.get_mut(x, y) = d as f32;
        *field.get_mut(x, y) = dir;
        d_max = d_max.max(d);
    }
    for _ in 0..SMOOTH_PASSES {
        field = box_smooth(&field, mask);
    }
    for k in 0..domain.len() {
        let (x, y) = domain.pixel(k);
        let [u, v] = *field.get(x, y);
        *azimuth.get_mut(x, y) = v.atan2(u) as f32;
        let d = f64::from(*distance.get(x, y));
        let t = if d_max > 0.0 { 1.0 - d / d_max } else { 1.0 };
        *weight.get_mut(x, y) = t.powf(exponent) as f32;
    }
    ConvexityPrior {
        azimuth,
        weight,
        distance,
        contour_share,
    }
}

/// Index into `seeds` of the closest seed to every pixel (two-pass vector
/// propagation over 8-neighbours; `usize::MAX` only for an empty seed list).
fn nearest_seed(w: usize, h: usize, seeds: &[(usize, usize, [f64; 2])]) -> Vec<usize> {
    let mut best = vec![usize::MAX; w * h];
    for (i, &(x, y, _)) in seeds.iter().enumerate() {
        best[y * w + x] = i;
    }
    let dist2 = |p: usize, s: usize| {
        let (sx, sy, _) = seeds[s];
        let (px, py) = (p % w, p / w);
        let (dx, dy) = (px as i64 - sx as i64, py as i64 - sy as i64);
        dx * dx + dy * dy
    };
    let relax = |best: &mut Vec<usize>, x: usize, y: usize, dx: isize, dy: isize| {
        let (nx, ny) = (x as isize + dx, y as isize + dy);
        if nx < 0 || ny < 0 || nx as usize >= w || ny as usize >= h {
            return;
        }
        let (p, q) = (y * w + x, ny as usize * w + nx as usize);
        let s = best[q];
        if s != usize::MAX && (best[p] == usize::MAX || dist2(p, s) < dist2(p, best[p])) {
            best[p] = s;
        }
    };
    for y in 0..h {
        for x in 0..w {
            for (dx, dy) in [(-1, 0), (-1, -1), (0, -1), (1, -1)] {
                relax(&mut best, x, y, dx, dy);
            }
        }
        for x in (0..w).rev() {
            relax(&mut best, x, y, 1, 0);
        }
    }
    for y in (0..h).rev() {
        for x in (0..w).rev() {
            for (dx, dy) in [(1, 0), (1, 1), (0, 1), (-1, 1)] {
                relax(&mut best, x, y, dx, dy);
            }
        }
        for x in 0..w {
            relax(&mut best, x, y, -1, 0);
        }
    }
    best
}

/// Masked box filter of the unit vectors, renormalised (vectors that cancel
/// keep their previous value).
fn box_smooth(field: &Image<[f64; 2]>, mask: &Mask) -> Image<[f64; 2]> {
    let (w, h) = field.size();
    let data: Vec<[f64; 2]> = (0..w * h)
        .into_par_iter()
        .map(|i| smooth_at(field, mask, i % w, i / w))
        .collect();
    Image::from_vec(w, h, data).expect("same size")
}

/// The masked box average of the unit vectors around `(x, y)`, renormalised.
fn smooth_at(field: &Image<[f64; 2]>, mask: &Mask, x: usize, y: usize) -> [f64; 2] {
    let (w, h) = field.size();
    if !*mask.get(x, y) {
        return [0.0; 2];
    }
    let mut sum = [0.0; 2];
    for dy in -SMOOTH_RADIUS..=SMOOTH_RADIUS {
        for dx in -SMOOTH_RADIUS..=SMOOTH_RADIUS {
            let (nx, ny) = (x as isize + dx, y as isize + dy);
            if nx < 0 || ny < 0 || nx as usize >= w || ny as usize >= h {
                continue;
            }
            if *mask.get(nx as usize, ny as usize) {
                let v = field.get(nx as usize, ny as usize);
                sum[0] += v[0];
                sum[1] += v[1];
            }
        }
    }
    let n = sum[0].hypot(sum[1]);
    if n > 1e-9 {
        [sum[0] / n, sum[1] / n]
    } else {
        *field.get(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_prior_points_radially_outwards() {
        let (n, c, r) = (64usize, 32.0f64, 25.0f64);
        let mask = Mask::from_fn(n, n, |x, y| {
            (x as f64 + 0.5 - c).powi(2) + (y as f64 + 0.5 - c).powi(2) < r * r
        });
        let prior = convexity_prior(&mask, DEFAULT_EXPONENT);
        let mut worst: f64 = 0.0;
        for y in 0..n {
            for x in 0..n {
                if !*mask.get(x, y) {
                    continue;
                }
                let (dx, dy) = (x as f64 + 0.5 - c, c - (y as f64 + 0.5));
                let rad = dx.hypot(dy);
                let d = f64::from(*prior.distance.get(x, y));
                // Outer ring: direction radial, distance r − |p|, weight near 1.
                if rad > 8.0 {
                    let diff = (f64::from(*prior.azimuth.get(x, y)) - dy.atan2(dx)).abs();
                    worst = worst.max(diff.min(2.0 * std::f64::consts::PI - diff));
                    assert!((d - (r - rad)).abs() < 1.5, "distance {d} at radius {rad}");
                }
            }
        }
        assert!(
            worst.to_degrees() < 10.0,
            "worst azimuth error {}°",
            worst.to_degrees()
        );
        // Weights: 1 on the boundary, tiny at the centre.
        assert_eq!(*prior.weight.get(32, 7), 1.0);
        assert!(*prior.weight.get(32, 32) < 1e-3);
    }

    #[test]
    fn contour_share_is_the_trusted_share_of_the_outline() {
        let (n, c, r) = (64usize, 32.0f64, 25.0f64);
        let mask = Mask::from_fn(n, n, |x, y| {
            (x as f64 + 0.5 - c).powi(2) + (y as f64 + 0.5 - c).powi(2) < r * r
        });
        let share = |trusted: &dyn Fn(usize) -> bool| {
            convexity_prior_trusted(&mask, DEFAULT_EXPONENT, |x, _, _| trusted(x)).contour_share
        };
        assert_eq!(share(&|_| true), 1.0);
        assert_eq!(share(&|_| false), 0.0);
        let right = share(&|x| x >= 32);
        assert!((right - 0.5).abs() < 0.02, "{right}");
    }

    #[test]
    fn frame_filling_mask_has_no_prior() {
        let prior = convexity_prior(&Mask::new(8, 8, true), DEFAULT_EXPONENT);
        assert!(prior.weight.data().iter().all(|&w| w == 0.0));
    }
}
