//! Polarization-driven adaptive region growing (PARG; SMSfP paper §4.5,
//! Algorithm 1): splits the object mask into regions of similar polarization
//! so that the convexity prior can be applied per locally convex piece.
//!
//! Every pixel carries the feature `F = [ρ, cos 2ψ, sin 2ψ, |∇ψ|]` (Eq. 20) and
//! the weight `W = [1 + λρ Rρ, 1 + λφ Rφ, 1 + λφ Rφ, 1]` (Eq. 25) built from the
//! reliabilities `R = exp(−σ²/max σ²)` of the local variances (Eqs. 21–24). A
//! region grows from a seed through a FIFO queue and accepts a neighbour `q`
//! when `‖W(q) ⊙ (F_q − F̄)‖₂ < τ` (Eq. 26), `F̄` being the region's running
//! mean feature.
//!
//! Choices the paper leaves open, made here:
//! - `|∇ψ|` comes from central differences (one-sided at the mask's edge, 0
//!   without a neighbour), each wrapped into `[−π/2, π/2)` because ψ is
//!   π-periodic, and is capped at [`PargParams::grad_cap`]: at a sphere's
//!   centre (`|∇ψ| = 1/distance`) and at AoP steps the pixel grid does not
//!   resolve ψ, and an unbounded channel would only fragment those spots.
//! - The AoP variance of Eq. 22 is the circular variance of the doubled angle,
//!   `1 − |mean e^{2iψ}|` over the window's mask pixels: π-periodic and blind to
//!   the 0/π wrap. The DoP variance is the plain variance over mask pixels.
//! - Seeds are planted one at a time, each growing to completion before the
//!   next: the next seed is the unlabelled mask pixel of highest reliability
//!   `Rρ·Rφ`, ties by raster index, so the result is deterministic and flat
//!   (trustworthy) areas are grown first.
//! - Neighbours are the 8 surrounding pixels, so constant features give one
//!   region per 8-connected mask component.
//! - Besides the paper's test against the region mean, the step from the
//!   dequeuing pixel `p` must satisfy `‖W ⊙ (F_q − F_p)‖₂ < τ_step`, with the
//!   weights of whichever of `p`, `q` gives the larger distance (the limb's own
//!   weights are low, its variance being high). Where an occluding limb meets
//!   a background of the same AoP, the mean test alone cannot see the edge
//!   (ψ agrees, ρ differs by ~0.2, which `τ` must tolerate or a sphere
//!   shatters) and without the step test a tilted plane swallows a wedge of a
//!   sphere in front of it; the limb's DoP jump is a sharp local step that
//!   smooth surfaces do not make. It holds while the background's DoP is ~0.1
//!   below the limb's: a 35°- or 50°-tilted plane behind a 30 px sphere
//!   (η = 1.5) stays apart, a 60° one (ρ ≈ 0.1) does not.
//! - Defaults, measured on 128² analytic scenes (η = 1.5 unless stated;
//!   regions after post-processing): `τ = 2` splits a sphere of radius 60 px
//!   into 8 regions (ψ turns through π twice around it, so sectors come in
//!   opposite pairs; `τ` = 1.5 / 2.5 / 3 give 12 / 8 / 6) and a 30 px one into
//!   10. `τ_step = 0.3` sits in the band [0.3, 0.35] where both the sphere
//!   over a 35° plane and two overlapping spheres (η 1.4 and 1.9) keep every
//!   region on one surface for τ from 1.5 to 2.5; 0.4 lets the plane in and
//!   0.25 fragments the contact so that merging mixes the spheres.
//! - Post-processing (paper: morphological hole filling, Gaussian smoothing):
//!   1. pockets of other labels that a region encloses are absorbed when they
//!      are at most [`PargParams::hole_area`] pixels and contain no pixel
//!      outside the mask (a real hole of the object stays a hole); larger
//!      pockets are kept, as a sphere in front of a plane is such a pocket;
//!   2. each pixel takes the label with the largest Gaussian-weighted vote
//!      (`smooth_sigma`, window radius `⌈2σ⌉`, mask pixels only) — the argmax
//!      of the Gaussian-filtered label indicators — once, but only a label
//!      whose region would have accepted the pixel by both growth tests: a
//!      plain vote erodes a convex region's rim into whatever surrounds it
//!      (34 limb pixels of a 30 px sphere went to the plane behind it);
//!   3. regions are split into 8-connected pieces (smoothing may cut one);
//!   4. pieces below `min_area` pixels merge, smallest first, into the adjacent
//!      region with the closest mean feature (weighted by the piece's mean
//!      `W`), preferring neighbours it touches through at least one step below
//!      `τ_step`: by mean feature alone, a fragment of one sphere's limb joined
//!      the other sphere's sector of the same AoP across the contact line;
//!      a piece without neighbours keeps its own label;
//!   5. ids are renumbered `1..=n` in raster order of each region's first pixel.
//! - The `|∇ψ|` cap changes how much the growth fragments (seeds on the
//!   sphere over the plane: 64 / 71 / 103 for caps 0.25 / 0.5 / none) but not
//!   the regions after merging (9 in each case); `min_area` 32 / 64 / 128
//!   gives 20 / 16 / 13 regions on the two spheres.
//! - Cost at 512² (sphere over a plane, release, 2 cores): 85 ms; with
//!   ±8.6° AoP noise (13,576 seeds) 150 ms.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sfp_core::{Error, Image, Mask, Result};
use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap, VecDeque};
use std::f32::consts::{FRAC_PI_2, PI};

/// Parameters of [`segment`].
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PargParams {
    /// DoP weight strength `λρ` (Eq. 25; paper default 2).
    pub lambda_rho: f64,
    /// AoP weight strength `λφ` (Eq. 25; paper default 2).
    pub lambda_phi: f64,
    /// Threshold of the distance to the region's mean feature (Eq. 26).
    pub tau: f64,
    /// Threshold of the distance to the neighbouring region pixel (see the
    /// module notes: it makes an occluding limb a boundary).
    pub tau_step: f64,
    /// Side of the variance window (Eqs. 21–22), odd.
    pub window: usize,
    /// Regions with fewer pixels merge into a neighbour.
    pub min_area: usize,
    /// Largest enclosed pocket (pixels) that hole filling absorbs.
    pub hole_area: usize,
    /// Sigma (pixels) of the Gaussian label vote; 0 switches smoothing off.
    pub smooth_sigma: f64,
    /// Cap of the `|∇ψ|` channel, radians per pixel.
    pub grad_cap: f64,
}

impl Default for PargParams {
    fn default() -> Self {
        PargParams {
            lambda_rho: 2.0,
            lambda_phi: 2.0,
            tau: 2.0,
            tau_step: 0.3,
            window: 5,
            min_area: 64,
            hole_area: 256,
            smooth_sigma: 1.0,
            grad_cap: 0.5,
        }
    }
}

/// What each stage did, for `run.json`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PargStats {
    /// Seeds planted; each grows one region, so also the number of regions
    /// before post-processing.
    pub seeds: usize,
    /// Enclosed pockets absorbed by hole filling.
    pub filled_holes: usize,
    /// Pixels whose label the Gaussian vote changed.
    pub smoothed_pixels: usize,
    /// Regions (8-connected pieces) merged into a neighbour for being small.
    pub merged_regions: usize,
}

/// The result of [`segment`].
#[derive(Clone, Debug)]
pub struct Segmentation {
    /// Region id per pixel: 0 outside the mask, 1..=regions inside; ids in
    /// raster order of each region's first pixel.
    pub labels: Image<u32>,
    pub regions: usize,
    pub stats: PargStats,
}

const NEIGHBOURS8: [(isize, isize); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];
pub(super) const NEIGHBOURS4: [(isize, isize); 4] = [(0, -1), (-1, 0), (1, 0), (0, 1)];

/// Segments the mask by Algorithm 1 plus post-processing (module notes).
pub fn segment(
    dop: &Image<f32>,
    aop: &Image<f32>,
    mask: &Mask,
    params: &PargParams,
) -> Result<Segmentation> {
    if !dop.same_size(mask) || !aop.same_size(mask) {
        return Err(Error::invalid(format!(
            "PARG: DoP {:?}, AoP {:?} and mask {:?} differ in size",
            dop.size(),
            aop.size(),
            mask.size()
        )));
    }
    if mask.count() == 0 {
        return Err(Error::invalid("PARG: the mask is empty"));
    }
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let non_negative = |v: f64| v.is_finite() && v >= 0.0;
    if !positive(params.tau)
        || !positive(params.tau_step)
        || !non_negative(params.lambda_rho)
        || !non_negative(params.lambda_phi)
        || !non_negative(params.smooth_sigma)
        || !non_negative(params.grad_cap)
        || params.window.is_multiple_of(2)
    {
        return Err(Error::invalid(format!(
            "PARG: invalid parameters {params:?} (thresholds > 0, weights, sigma and cap ≥ 0, odd window)"
        )));
    }
    let grid = Grid {
        w: mask.width(),
        h: mask.height(),
        mask: mask.data(),
    };
    let features = Features::new(&grid, dop.data(), aop.data(), params);
    let (mut labels, seeds) = grow(&grid, &features, params);
    let filled_holes = fill_holes(&grid, &mut labels, seeds, params.hole_area);
    let smoothed_pixels = smooth(&grid, &mut labels, seeds, &features, params);
    let pieces = relabel_components(&grid, &mut labels);
    let merged_regions = merge_small(&grid, &mut labels, pieces, &features, params);
    let regions = relabel_components(&grid, &mut labels);
    Ok(Segmentation {
        labels: Image::from_vec(grid.w, grid.h, labels)?,
        regions,
        stats: PargStats {
            seeds,
            filled_holes,
            smoothed_pixels,
            merged_regions,
        },
    })
}

/// Image geometry and mask, shared by the stages.
struct Grid<'a> {
    w: usize,
    h: usize,
    mask: &'a [bool],
}

impl Grid<'_> {
    /// Linear index of `(x, y) + (dx, dy)` when that pixel is inside the mask.
    #[inline]
    fn neighbour(&self, i: usize, (dx, dy): (isize, isize)) -> Option<usize> {
        let x = (i % self.w) as isize + dx;
        let y = (i / self.w) as isize + dy;
        if x < 0 || y < 0 || x as usize >= self.w || y as usize >= self.h {
            return None;
        }
        let j = y as usize * self.w + x as usize;
        self.mask[j].then_some(j)
    }
}

/// Per-pixel features (Eq. 20), weights `[wρ, wφ]` (Eq. 25) and seed
/// reliability `Rρ·Rφ`; zeros outside the mask.
struct Features {
    f: Vec<[f32; 4]>,
    w: Vec<[f32; 2]>,
    reliability: Vec<f32>,
}

impl Features {
    fn new(grid: &Grid, dop: &[f32], aop: &[f32], params: &PargParams) -> Self {
        let n = grid.w * grid.h;
        let cap = params.grad_cap as f32;
        let wrap = |d: f32| (d + FRAC_PI_2).rem_euclid(PI) - FRAC_PI_2;
        // One derivative: central where both sides are in the mask, else one-sided.
        let derivative = |i: usize, step: (isize, isize)| {
            let back = grid.neighbour(i, (-step.0, -step.1));
            match (back, grid.neighbour(i, step)) {
                (Some(a), Some(b)) => wrap(aop[b] - aop[a]) / 2.0,
                (Some(a), None) => wrap(aop[i] - aop[a]),
                (None, Some(b)) => wrap(aop[b] - aop[i]),
                (None, None) => 0.0,
            }
        };
        let f: Vec<[f32; 4]> = (0..n)
            .into_par_iter()
            .map(|i| {
                if !grid.mask[i] {
                    return [0.0; 4];
                }
                let g = derivative(i, (1, 0)).hypot(derivative(i, (0, 1)));
                let (s, c) = (2.0 * aop[i]).sin_cos();
                [dop[i], c, s, g.min(cap)]
            })
            .collect();
        // Local variances (Eqs. 21–22): plain for ρ, circular (doubled angle) for ψ.
        // Beyond `w + h` a window reaches no pixel more (and a huge one
        // would loop without end).
        let r = (params.window / 2).min(grid.w + grid.h) as isize;
        let variances: Vec<[f64; 2]> = (0..n)
            .into_par_iter()
            .map(|i| {
                if !grid.mask[i] {
                    return [0.0; 2];
                }
                let (mut count, mut sum, mut sum2, mut c, mut s) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
                for dy in -r..=r {
                    for dx in -r..=r {
                        if let Some(j) = grid.neighbour(i, (dx, dy)) {
                            let rho = f64::from(f[j][0]);
                            count += 1.0;
                            sum += rho;
                            sum2 += rho * rho;
                            c += f64::from(f[j][1]);
                            s += f64::from(f[j][2]);
                        }
                    }
                }
                let mean = sum / count;
                let var_rho = (sum2 / count - mean * mean).max(0.0);
                let var_psi = (1.0 - c.hypot(s) / count).max(0.0);
                [var_rho, var_psi]
            })
            .collect();
        let max = variances
            .iter()
            .zip(grid.mask)
            .filter(|&(_, &m)| m)
            .fold([0.0f64; 2], |m, (v, _)| [m[0].max(v[0]), m[1].max(v[1])]);
        // Eqs. 23–24; a constant channel (max 0) is fully reliable.
        let reliability_of = |v: f64, max: f64| if max > 0.0 { (-v / max).exp() } else { 1.0 };
        let (lr, lp) = (params.lambda_rho, params.lambda_phi);
        let mut w = vec![[0.0f32; 2]; n];
        let mut reliability = vec![0.0f32; n];
        for i in (0..n).filter(|&i| grid.mask[i]) {
            let rr = reliability_of(variances[i][0], max[0]);
            let rp = reliability_of(variances[i][1], max[1]);
            w[i] = [(1.0 + lr * rr) as f32, (1.0 + lp * rp) as f32];
            reliability[i] = (rr * rp) as f32;
        }
        Features { f, w, reliability }
    }

    /// `‖W(q) ⊙ (F_q − other)‖₂` (Eq. 26).
    #[inline]
    fn distance(&self, q: usize, other: &[f32; 4]) -> f32 {
        let (f, w) = (&self.f[q], &self.w[q]);
        let d = [
            w[0] * (f[0] - other[0]),
            w[1] * (f[1] - other[1]),
            w[1] * (f[2] - other[2]),
            f[3] - other[3],
        ];
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt()
    }

    /// Distance between neighbours `i` and `j`, weighted by the more reliable
    /// of the two: at a limb the weights drop (high variance) just where
    /// the step must count.
    #[inline]
    fn step(&self, i: usize, j: usize) -> f32 {
        self.distance(i, &self.f[j])
            .max(self.distance(j, &self.f[i]))
    }
}

/// Algorithm 1: labels `1..=seeds` for every mask pixel, and the seed count.
fn grow(grid: &Grid, features: &Features, params: &PargParams) -> (Vec<u32>, usize) {
    let rel = &features.reliability;
    let mut order: Vec<usize> = (0..grid.mask.len()).filter(|&i| grid.mask[i]).collect();
    order.sort_by(|&a, &b| rel[b].total_cmp(&rel[a]).then(a.cmp(&b)));
    let (tau, tau_step) = (params.tau as f32, params.tau_step as f32);
    let mut labels = vec![0u32; grid.mask.len()];
    let mut queue = VecDeque::new();
    let mut seeds = 0u32;
    for &seed in &order {
        if labels[seed] != 0 {
            continue;
        }
        seeds += 1;
        labels[seed] = seeds;
        let mut sum = features.f[seed].map(f64::from);
        let mut count = 1.0f64;
        queue.push_back(seed);
        while let Some(p) = queue.pop_front() {
            for step in NEIGHBOURS8 {
                let Some(q) = grid.neighbour(p, step) else {
                    continue;
                };
                if labels[q] != 0 {
                    continue;
                }
                let mean = sum.map(|s| (s / count) as f32);
                if features.distance(q, &mean) < tau && features.step(p, q) < tau_step {
                    labels[q] = seeds;
                    for (s, v) in sum.iter_mut().zip(features.f[q]) {
                        *s += f64::from(v);
                    }
                    count += 1.0;
                    queue.push_back(q);
                }
            }
        }
    }
    (labels, seeds as usize)
}

/// Absorbs small enclosed pockets (module notes, step 1); returns their number.
///
/// Per region, the complement of the region inside its bounding box (grown by
/// one pixel) is flooded from the box's edge through 4-neighbours (the dual
/// of the 8-connected regions); what the flood misses is enclosed.
fn fill_holes(grid: &Grid, labels: &mut [u32], regions: usize, hole_area: usize) -> usize {
    let mut bbox = vec![[usize::MAX, usize::MAX, 0, 0]; regions + 1];
    for (i, &l) in labels.iter().enumerate().filter(|&(_, &l)| l != 0) {
        let (x, y) = (i % grid.w, i / grid.w);
        let b = &mut bbox[l as usize];
        *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    }
    // Scratch, reused across regions: 0 unvisited, 1 region or flooded, 2 pocket.
    let mut state: Vec<u8> = Vec::new();
    let mut stack: Vec<(usize, usize)> = Vec::new();
    let mut pocket: Vec<usize> = Vec::new();
    let mut filled = 0;
    for (label, &[x0, y0, x1, y1]) in bbox.iter().enumerate().skip(1) {
        let label = label as u32;
        let (x0, y0) = (x0.saturating_sub(1), y0.saturating_sub(1));
        let (x1, y1) = ((x1 + 1).min(grid.w - 1), (y1 + 1).min(grid.h - 1));
        let (bw, bh) = (x1 + 1 - x0, y1 + 1 - y0);
        if bw < 3 || bh < 3 {
            continue; // too thin to enclose anything
        }
        let at = |bx: usize, by: usize| (y0 + by) * grid.w + x0 + bx;
        state.clear();
        state.resize(bw * bh, 0);
        for by in 0..bh {
            for bx in 0..bw {
                if labels[at(bx, by)] == label {
                    state[by * bw + bx] = 1;
                }
            }
        }
        let flood = |state: &mut [u8], stack: &mut Vec<(usize, usize)>, mark: u8| {
            while let Some((bx, by)) = stack.pop() {
                for (dx, dy) in NEIGHBOURS4 {
                    let (nx, ny) = (bx as isize + dx, by as isize + dy);
                    if nx < 0 || ny < 0 || nx as usize >= bw || ny as usize >= bh {
                        continue;
                    }
                    let k = ny as usize * bw + nx as usize;
                    if state[k] == 0 {
                        state[k] = mark;
                        stack.push((nx as usize, ny as usize));
                    }
                }
            }
        };
        for by in 0..bh {
            for bx in 0..bw {
                let edge = bx == 0 || by == 0 || bx == bw - 1 || by == bh - 1;
                if edge && state[by * bw + bx] == 0 {
                    state[by * bw + bx] = 1;
                    stack.push((bx, by));
                    flood(&mut state, &mut stack, 1);
                }
            }
        }
        for by in 1..bh - 1 {
            for bx in 1..bw - 1 {
                if state[by * bw + bx] != 0 {
                    continue;
                }
                // A pocket: collect it by flooding with mark 2.
                state[by * bw + bx] = 2;
                pocket.clear();
                stack.push((bx, by));
                let mut head = 0;
                pocket.push(at(bx, by));
                while head < stack.len() {
                    let (px, py) = stack[head];
                    head += 1;
                    for (dx, dy) in NEIGHBOURS4 {
                        let (nx, ny) = ((px as isize + dx) as usize, (py as isize + dy) as usize);
                        let k = ny * bw + nx;
                        if state[k] == 0 {
                            state[k] = 2;
                            stack.push((nx, ny));
                            pocket.push(at(nx, ny));
                        }
                    }
                }
                stack.clear();
                if pocket.len() <= hole_area && pocket.iter().all(|&i| grid.mask[i]) {
                    for &i in &pocket {
                        labels[i] = label;
                    }
                    filled += 1;
                }
            }
        }
    }
    filled
}

/// Gaussian label vote (module notes, step 2); returns the changed pixels.
fn smooth(
    grid: &Grid,
    labels: &mut [u32],
    regions: usize,
    features: &Features,
    params: &PargParams,
) -> usize {
    let sigma = params.smooth_sigma;
    if sigma <= 0.0 {
        return 0;
    }
    let (tau, tau_step) = (params.tau as f32, params.tau_step as f32);
    let mut sums = vec![Sums::default(); regions + 1];
    for (i, &l) in labels.iter().enumerate().filter(|&(_, &l)| l != 0) {
        sums[l as usize].add(features, i);
    }
    let means: Vec<[f32; 4]> = sums.iter().map(|s| s.mean().map(|v| v as f32)).collect();
    let r = (2.0 * sigma).ceil() as isize;
    let side = (2 * r + 1) as usize;
    let kernel: Vec<f32> = (0..side * side)
        .map(|k| {
            let (dx, dy) = ((k % side) as isize - r, (k / side) as isize - r);
            (-((dx * dx + dy * dy) as f64) / (2.0 * sigma * sigma)).exp() as f32
        })
        .collect();
    let old: &[u32] = labels;
    // Whether region `l` would have accepted pixel `i` by both growth tests.
    let admissible = |i: usize, l: u32| {
        features.distance(i, &means[l as usize]) < tau
            && NEIGHBOURS8.iter().any(|&step| {
                grid.neighbour(i, step)
                    .is_some_and(|j| old[j] == l && features.step(i, j) < tau_step)
            })
    };
    let voted: Vec<u32> = (0..grid.h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let mut votes: Vec<(u32, f32)> = Vec::with_capacity(side * side);
            let kernel = &kernel;
            (0..grid.w).map(move |x| {
                let i = y * grid.w + x;
                if !grid.mask[i] {
                    return 0;
                }
                votes.clear();
                for (k, &g) in kernel.iter().enumerate() {
                    let step = ((k % side) as isize - r, (k / side) as isize - r);
                    if let Some(j) = grid.neighbour(i, step) {
                        match votes.iter_mut().find(|v| v.0 == old[j]) {
                            Some(v) => v.1 += g,
                            None => votes.push((old[j], g)),
                        }
                    }
                }
                // The largest admissible vote; ties keep the current label,
                // then go to the smaller id.
                let own = votes.iter().find(|v| v.0 == old[i]).map_or(0.0, |v| v.1);
                let mut best = (old[i], own);
                for &(l, v) in &votes {
                    let wins = v > best.1 || (v == best.1 && best.0 != old[i] && l < best.0);
                    if wins && l != old[i] && admissible(i, l) {
                        best = (l, v);
                    }
                }
                best.0
            })
        })
        .collect();
    let changed = voted.iter().zip(old.iter()).filter(|(a, b)| a != b).count();
    labels.copy_from_slice(&voted);
    changed
}

/// Pixel count and feature and weight sums of a region.
#[derive(Clone, Default)]
struct Sums {
    area: usize,
    f: [f64; 4],
    w: [f64; 2],
}

impl Sums {
    fn add(&mut self, features: &Features, i: usize) {
        self.area += 1;
        for (s, v) in self.f.iter_mut().zip(features.f[i]) {
            *s += f64::from(v);
        }
        for (s, v) in self.w.iter_mut().zip(features.w[i]) {
            *s += f64::from(v);
        }
    }

    fn absorb(&mut self, other: &Sums) {
        self.area += other.area;
        for (s, v) in self.f.iter_mut().zip(other.f) {
            *s += v;
        }
        for (s, v) in self.w.iter_mut().zip(other.w) {
            *s += v;
        }
    }

    fn mean(&self) -> [f64; 4] {
        self.f.map(|v| v / self.area.max(1) as f64)
    }

    fn mean_weight(&self) -> [f64; 2] {
        self.w.map(|v| v / self.area.max(1) as f64)
    }
}

/// Renumbers the 8-connected pieces of equal label `1..=n` in raster order of
/// their first pixel; returns `n`.
fn relabel_components(grid: &Grid, labels: &mut [u32]) -> usize {
    let mut out = vec![0u32; labels.len()];
    let mut queue = VecDeque::new();
    let mut n = 0u32;
    for start in 0..labels.len() {
        if !grid.mask[start] || out[start] != 0 {
            continue;
        }
        n += 1;
        out[start] = n;
        queue.push_back(start);
        while let Some(p) = queue.pop_front() {
            for step in NEIGHBOURS8 {
                if let Some(q) = grid.neighbour(p, step)
                    && out[q] == 0
                    && labels[q] == labels[p]
                {
                    out[q] = n;
                    queue.push_back(q);
                }
            }
        }
    }
    labels.copy_from_slice(&out);
    n as usize
}

/// Merges regions below `min_area` into their most similar neighbour
/// (module notes, step 4); returns the number of merges. Ids stay in
/// `1..=regions` with gaps; the caller renumbers.
fn merge_small(
    grid: &Grid,
    labels: &mut [u32],
    regions: usize,
    features: &Features,
    params: &PargParams,
) -> usize {
    let (min_area, tau_step) = (params.min_area, params.tau_step as f32);
    let mut sums = vec![Sums::default(); regions + 1];
    // Neighbour id → whether some contact between the two is a weak step.
    let mut adjacent: Vec<BTreeMap<u32, bool>> = vec![BTreeMap::new(); regions + 1];
    for (i, &l) in labels.iter().enumerate().filter(|&(_, &l)| l != 0) {
        let l = l as usize;
        sums[l].add(features, i);
        // Half of the 8-neighbourhood suffices: pairs are recorded both ways.
        for step in &NEIGHBOURS8[4..] {
            if let Some(j) = grid.neighbour(i, *step) {
                let m = labels[j];
                if m as usize != l {
                    let weak = features.step(i, j) < tau_step;
                    *adjacent[l].entry(m).or_default() |= weak;
                    *adjacent[m as usize].entry(l as u32).or_default() |= weak;
                }
            }
        }
    }
    let mut heap: BinaryHeap<Reverse<(usize, u32)>> = (1..=regions)
        .filter(|&l| sums[l].area < min_area)
        .map(|l| Reverse((sums[l].area, l as u32)))
        .collect();
    let mut target: Vec<u32> = (0..=regions as u32).collect();
    let mut merged = 0;
    while let Some(Reverse((a, s))) = heap.pop() {
        let s_ = s as usize;
        if target[s_] != s || sums[s_].area != a {
            continue; // merged away or grown since it was queued
        }
        let (fs, w) = (sums[s_].mean(), sums[s_].mean_weight());
        let distance = |t: u32| {
            let ft = sums[t as usize].mean();
            let d: [f64; 4] = std::array::from_fn(|k| fs[k] - ft[k]);
            ((w[0] * d[0]).powi(2) + (w[1] * d[1]).powi(2) + (w[1] * d[2]).powi(2) + d[3].powi(2))
                .sqrt()
        };
        // Neighbours behind a weak contact first; neighbours iterate in id
        // order, so ties go to the smaller id.
        let Some(t) = adjacent[s_]
            .iter()
            .min_by(|&(&a, &weak_a), &(&b, &weak_b)| {
                weak_b
                    .cmp(&weak_a)
                    .then(distance(a).total_cmp(&distance(b)))
            })
            .map(|(&t, _)| t)
        else {
            continue; // an isolated piece keeps its label
        };
        let t_ = t as usize;
        target[s_] = t;
        let absorbed = sums[s_].clone();
        sums[t_].absorb(&absorbed);
        for (n, weak) in std::mem::take(&mut adjacent[s_]) {
            adjacent[n as usize].remove(&s);
            if n != t {
                *adjacent[n as usize].entry(t).or_default() |= weak;
                *adjacent[t_].entry(n).or_default() |= weak;
            }
        }
        merged += 1;
        if sums[t_].area < min_area {
            heap.push(Reverse((sums[t_].area, t)));
        }
    }
    for l in labels.iter_mut().filter(|l| **l != 0) {
        let mut t = *l;
        while target[t as usize] != t {
            t = target[t as usize];
        }
        *l = t;
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::fresnel::diffuse_dop;

    /// A synthetic view: per pixel `Some((normal, η, surface id))` or `None`
    /// outside the mask. Returns DoP, AoP, mask and the surface ids.
    /// Normal, η and surface id of a mask pixel.
    type Surface = Option<([f64; 3], f64, u8)>;

    fn scene(
        n: usize,
        f: impl Fn(f64, f64) -> Surface,
    ) -> (Image<f32>, Image<f32>, Mask, Image<u8>) {
        let px: Vec<_> = (0..n * n)
            .map(|i| f((i % n) as f64 + 0.5, (i / n) as f64 + 0.5))
            .collect();
        let img = |g: &dyn Fn(&Surface) -> f32| {
            Image::from_vec(n, n, px.iter().map(g).collect()).unwrap()
        };
        let dop = img(&|p| p.map_or(0.0, |(nrm, eta, _)| diffuse_dop(nrm[2].acos(), eta) as f32));
        let aop = img(&|p| {
            p.map_or(0.0, |(nrm, _, _)| {
                nrm[1].atan2(nrm[0]).rem_euclid(std::f64::consts::PI) as f32
            })
        });
        let mask = Mask::from_vec(n, n, px.iter().map(Option::is_some).collect()).unwrap();
        let ids = Image::from_vec(n, n, px.iter().map(|p| p.map_or(0, |p| p.2)).collect()).unwrap();
        (dop, aop, mask, ids)
    }

    /// Camera-frame normal of a sphere (centre and radius in pixels) at pixel
    /// position `(x, y)` (+y up means the row axis flips).
    fn sphere(x: f64, y: f64, cx: f64, cy: f64, r: f64) -> Option<[f64; 3]> {
        let (u, v) = ((x - cx) / r, (cy - y) / r);
        let s = u * u + v * v;
        (s < 1.0).then(|| [u, v, (1.0 - s).sqrt()])
    }

    fn tilted(theta_deg: f64, azimuth_deg: f64) -> [f64; 3] {
        let (t, a) = (theta_deg.to_radians(), azimuth_deg.to_radians());
        [t.sin() * a.cos(), t.sin() * a.sin(), t.cos()]
    }

    /// Pixels of each region that do not belong to its majority surface.
    fn leaks(labels: &Image<u32>, regions: usize, ids: &Image<u8>) -> Vec<usize> {
        let mut counts = vec![[0usize; 256]; regions + 1];
        for (&l, &id) in labels.data().iter().zip(ids.data()) {
            counts[l as usize][id as usize] += 1;
        }
        counts[1..]
            .iter()
            .map(|c| c.iter().sum::<usize>() - c.iter().max().unwrap())
            .collect()
    }

    /// Labels are `1..=regions` inside the mask, in raster order of first
    /// pixel, 0 outside.
    fn check_labels(seg: &Segmentation, mask: &Mask) {
        let mut next = 1;
        for (&l, &m) in seg.labels.data().iter().zip(mask.data()) {
            assert_eq!(l == 0, !m);
            assert!(l as usize <= seg.regions);
            if l == next {
                next += 1;
            } else {
                assert!(l < next, "label {l} before {next}");
            }
        }
        assert_eq!(next as usize, seg.regions + 1);
    }

    #[test]
    fn contact_between_spheres_is_a_boundary() {
        // Sphere B (η = 1.9) in front of the larger sphere A (η = 1.4).
        let (dop, aop, mask, ids) = scene(128, |x, y| {
            sphere(x, y, 90.0, 64.0, 22.0)
                .map(|n| (n, 1.9, 2))
                .or_else(|| sphere(x, y, 42.0, 64.0, 32.0).map(|n| (n, 1.4, 1)))
        });
        let seg = segment(&dop, &aop, &mask, &PargParams::default()).unwrap();
        check_labels(&seg, &mask);
        let leaks = leaks(&seg.labels, seg.regions, &ids);
        eprintln!(
            "two spheres: {} regions, {:?}, leaks {leaks:?}",
            seg.regions, seg.stats
        );
        assert!(leaks.iter().all(|&l| l <= 3), "leaks {leaks:?}");
    }

    #[test]
    fn sphere_outline_over_a_plane_is_a_boundary() {
        let plane = tilted(35.0, 20.0);
        let (dop, aop, mask, ids) = scene(128, |x, y| {
            sphere(x, y, 64.0, 64.0, 30.0)
                .map(|n| (n, 1.5, 1))
                .or_else(|| {
                    (x > 4.0 && x < 124.0 && y > 4.0 && y < 124.0).then_some((plane, 1.5, 2))
                })
        });
        let seg = segment(&dop, &aop, &mask, &PargParams::default()).unwrap();
        check_labels(&seg, &mask);
        let leaks = leaks(&seg.labels, seg.regions, &ids);
        eprintln!(
            "sphere over plane: {} regions, {:?}, leaks {leaks:?}",
            seg.regions, seg.stats
        );
        assert!(leaks.iter().all(|&l| l <= 3), "leaks {leaks:?}");
    }

    #[test]
    fn a_window_beyond_the_image_is_the_whole_image() {
        let (dop, aop, mask, _) = scene(24, |x, y| {
            sphere(x, y, 12.0, 12.0, 10.0).map(|n| (n, 1.5, 1))
        });
        let with = |window: usize| {
            let params = PargParams {
                window,
                ..PargParams::default()
            };
            segment(&dop, &aop, &mask, &params).unwrap().labels
        };
        assert_eq!(with(usize::MAX), with(97));
    }

    #[test]
    fn sphere_splits_into_a_few_sectors() {
        let (dop, aop, mask, _) = scene(128, |x, y| {
            sphere(x, y, 64.0, 64.0, 60.0).map(|n| (n, 1.5, 1))
        });
        let seg = segment(&dop, &aop, &mask, &PargParams::default()).unwrap();
        check_labels(&seg, &mask);
        eprintln!("sphere r=60: {} regions, {:?}", seg.regions, seg.stats);
        assert!((2..=16).contains(&seg.regions), "{} regions", seg.regions);
    }

    #[test]
    fn constant_features_give_one_region_per_component() {
        // Two rectangles, the first with a pixel touching it only diagonally.
        let mask = Mask::from_fn(40, 30, |x, y| {
            (2..15).contains(&x) && (2..20).contains(&y)
                || (20..38).contains(&x) && (5..25).contains(&y)
                || (x, y) == (15, 20)
        });
        let dop = Image::new(40, 30, 0.1f32);
        let aop = Image::new(40, 30, 1.0f32);
        let seg = segment(&dop, &aop, &mask, &PargParams::default()).unwrap();
        check_labels(&seg, &mask);
        assert_eq!(seg.regions, 2);
        assert_eq!(*seg.labels.get(15, 20), *seg.labels.get(2, 2));
    }

    #[test]
    fn small_regions_merge_unless_isolated() {
        // A noisy sphere fragments; a separate 3×3 blob cannot merge.
        let mut state = 12345u64;
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f64 / (1u64 << 24) as f64 - 0.5
        };
        let (mut dop, mut aop, mut mask, _) = scene(96, |x, y| {
            sphere(x, y, 44.0, 44.0, 40.0).map(|n| (n, 1.5, 1))
        });
        for (d, a) in dop.data_mut().iter_mut().zip(aop.data_mut()) {
            *d += 0.02 * noise() as f32;
            *a = (*a + 0.3 * noise() as f32).rem_euclid(PI);
        }
        for y in 90..93 {
            for x in 90..93 {
                *mask.get_mut(x, y) = true;
            }
        }
        let params = PargParams {
            min_area: 150,
            ..PargParams::default()
        };
        let seg = segment(&dop, &aop, &mask, &params).unwrap();
        check_labels(&seg, &mask);
        eprintln!("noisy sphere: {} regions, {:?}", seg.regions, seg.stats);
        assert!(seg.stats.merged_regions > 0);
        let mut area = vec![0usize; seg.regions + 1];
        for &l in seg.labels.data() {
            area[l as usize] += 1;
        }
        let blob = *seg.labels.get(91, 91) as usize;
        assert_eq!(area[blob], 9);
        for (l, &a) in area.iter().enumerate().skip(1) {
            assert!(
                l == blob || a >= params.min_area,
                "region {l} has {a} pixels"
            );
        }
    }

    #[test]
    fn aop_wrapping_through_zero_stays_one_region() {
        // ψ within ±0.5° of 0, i.e. values near 0 and near π.
        let (n, mut state) = (64, 7u64);
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        let dop = Image::from_fn(n, n, |_, _| 0.05 + 0.004 * noise());
        let aop = Image::from_fn(n, n, |_, _| (1f32.to_radians() * noise()).rem_euclid(PI));
        assert!(aop.data().iter().any(|&a| a > 3.0) && aop.data().iter().any(|&a| a < 0.1));
        let mask = Mask::new(n, n, true);
        let seg = segment(&dop, &aop, &mask, &PargParams::default()).unwrap();
        // One seed: the growth itself, not the merging, keeps it whole.
        assert_eq!((seg.regions, seg.stats.seeds), (1, 1), "{:?}", seg.stats);
    }

    #[test]
    fn degenerate_inputs() {
        let (dop, aop) = (Image::new(5, 4, 0.1f32), Image::new(5, 4, 0.3f32));
        let empty = Mask::new(5, 4, false);
        assert!(segment(&dop, &aop, &empty, &PargParams::default()).is_err());
        let wrong = Mask::new(4, 4, true);
        assert!(segment(&dop, &aop, &wrong, &PargParams::default()).is_err());
        let mut one = empty.clone();
        *one.get_mut(2, 1) = true;
        let seg = segment(&dop, &aop, &one, &PargParams::default()).unwrap();
        assert_eq!(seg.regions, 1);
        check_labels(&seg, &one);
        // NaN inputs do not panic, and every mask pixel is still labelled.
        let nan = Image::new(5, 4, f32::NAN);
        let full = Mask::new(5, 4, true);
        let seg = segment(&nan, &aop, &full, &PargParams::default()).unwrap();
        check_labels(&seg, &full);
    }

    /// `cargo test -p sfp-reconstruct --release --lib parg_timing -- --ignored --nocapture`
    #[test]
    #[ignore = "a timing at 512² or more printing seconds (slow in CI); run with --ignored --nocapture"]
    fn parg_timing_512() {
        let plane = tilted(35.0, 20.0);
        let (dop, aop, mask, _) = scene(512, |x, y| {
            sphere(x, y, 256.0, 256.0, 150.0)
                .map(|n| (n, 1.5, 1))
                .or_else(|| {
                    (x > 16.0 && x < 496.0 && y > 16.0 && y < 496.0).then_some((plane, 1.5, 2))
                })
        });
        let start = std::time::Instant::now();
        let seg = segment(&dop, &aop, &mask, &PargParams::default()).unwrap();
        eprintln!(
            "512²: {:?}, {} regions, {:?}",
            start.elapsed(),
            seg.regions,
            seg.stats
        );
        // Noise fragments the growth into many seeds: the slow case.
        let mut noisy = aop.clone();
        for (k, a) in noisy.data_mut().iter_mut().enumerate() {
            let h = (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
            *a = (*a + 0.3 * (h as f32 / (1u64 << 24) as f32 - 0.5)).rem_euclid(PI);
        }
        let start = std::time::Instant::now();
        let seg = segment(&dop, &noisy, &mask, &PargParams::default()).unwrap();
        eprintln!(
            "512² noisy: {:?}, {} regions, {:?}",
            start.elapsed(),
            seg.regions,
            seg.stats
        );
    }
}
