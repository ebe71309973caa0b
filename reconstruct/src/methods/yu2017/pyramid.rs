//! Coarse to fine (spec §3.5): the ratio stage on every `step`-th pixel,
//! `step` halving from the coarsest level (about [`Settings::coarsest`]
//! pixels across) to the finest, each level started from the previous
//! one's heights; then the full stage on the finest level.
//!
//! The first level starts from a hemisphere over the whole grid. A later
//! level starts from the previous heights interpolated bilinearly and
//! doubled: heights are in pixels of their level, so the slopes stay what
//! the previous level found (the authors keep the values, Q11, which
//! halves every slope at each level: with more than their five levels, or
//! a steep object, the finest level starts too flat to recover within
//! its rounds: 16° instead of 0.9° MAE on a 128² sphere). The authors'
//! handling is kept otherwise (Q5): heights outside the previous mask count as
//! 0, so a new rim pixel blends with 0 and starts steep, the way the
//! outward prior wants it; negative heights are lifted by the grid's
//! minimum; the last row repeats the one above. The port's steps keep the
//! hemisphere's mean height (each step has zero mean), so the lift rarely
//! applies, as in theirs.

use super::full::{FullWeights, Shading, solve_full};
use super::level::{Level, Observations};
use super::levenberg::Outcome;
use super::ratio::{RatioWeights, solve_ratio};
use super::shading::{estimate_albedo, estimate_light};
use crate::solver::lsq::Solver;
use crate::stage;
use sfp_core::{Error, Image, Result};
use std::time::Instant;

/// What the full stage estimates.
#[derive(Clone, Copy, Debug)]
pub enum FullShading {
    /// The light, with a uniform albedo.
    Light,
    /// Each pixel's albedo under this known light.
    Albedo([f64; 3]),
}

/// Everything the pyramid runs with.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub eta: f64,
    /// Pixels across the larger side at the coarsest level, at least.
    pub coarsest: usize,
    /// The finest level's step (1: full resolution; the authors' demo
    /// stops at 2).
    pub finest_step: usize,
    pub ratio: RatioWeights,
    /// The full stage, or `None` to stop after the ratio stage.
    pub full: Option<(FullWeights, FullShading)>,
    /// The authors' specular phase (Q1), Laplacian (Q3) and heights kept
    /// unscaled between levels (Q11).
    pub authors_quirks: bool,
}

/// One level's record.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LevelRecord {
    pub step: usize,
    pub unknowns: usize,
    pub prior_pixels: usize,
    pub runs: Vec<Outcome>,
}

/// The result at the finest level's grid.
pub struct Output {
    pub level: Level,
    /// Heights after the ratio stage, per unknown of `level`.
    pub ratio: Vec<f64>,
    /// Heights after the full stage.
    pub full: Option<Vec<f64>>,
    pub shading: Option<Shading>,
    pub levels: Vec<LevelRecord>,
    pub full_runs: Vec<Outcome>,
    pub seconds_ratio: f64,
    pub seconds_full: f64,
}

impl Output {
    /// The final heights (full stage when it ran).
    pub fn heights(&self) -> &[f64] {
        self.full.as_deref().unwrap_or(&self.ratio)
    }
}

/// Runs both stages on `obs`.
pub fn run(obs: &Observations, settings: &Settings, solver: &mut Solver) -> Result<Output> {
    let (w, h) = obs.mask.size();
    let mut step = settings.finest_step.max(1);
    while w.max(h).div_ceil(2 * step) >= settings.coarsest.max(1) {
        step *= 2;
    }
    let start = Instant::now();
    let mut previous: Option<(Image<f64>, usize)> = None;
    let mut levels = Vec::new();
    let mut finest = None;
    loop {
        stage::enter(&format!("ratio stage, every {step}. pixel"));
        if let Some(level) = Level::new(obs, step, settings.eta, settings.authors_quirks) {
            let (lw, lh) = level.domain.size();
            let grid = match &previous {
                Some((z, previous_step)) => {
                    let scale = if settings.authors_quirks {
                        1.0
                    } else {
                        (*previous_step / step) as f64
                    };
                    upsample(z, lw, lh).map(|v| v * scale)
                }
                None => hemisphere(lw, lh),
            };
            let mut z = level.domain.gather(&grid);
            let runs = solve_ratio(&level, &mut z, settings.ratio, solver)?;
            levels.push(LevelRecord {
                step,
                unknowns: level.domain.len(),
                prior_pixels: level.targets.len(),
                runs,
            });
            previous = Some((level.domain.scatter(&z, f64::NAN), step));
            finest = Some((level, z));
        }
        if step <= settings.finest_step.max(1) {
            break;
        }
        step /= 2;
    }
    let Some((level, ratio)) = finest else {
        return Err(Error::invalid(
            "yu2017: no pixel of the mask has a horizontal and a vertical neighbour",
        ));
    };
    let seconds_ratio = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let (full, shading, full_runs) = match settings.full {
        None => (None, None, Vec::new()),
        Some((weights, kind)) => {
            stage::enter("full stage");
            let shading = match kind {
                FullShading::Light => estimate_light(&level, &ratio)?,
                FullShading::Albedo(s) => estimate_albedo(&level, &ratio, s),
            };
            let mut z = ratio.clone();
            let runs = solve_full(&level, &shading, &mut z, weights, solver)?;
            (Some(z), Some(shading), runs)
        }
    };
    Ok(Output {
        level,
        ratio,
        full,
        shading,
        levels,
        full_runs,
        seconds_ratio,
        seconds_full: start.elapsed().as_secs_f64(),
    })
}

/// The first level's start: `√(max d² − d²)` with `d` the distance from the
/// grid's centre pixel (1-based `⌈H/2⌉, ⌈W/2⌉`, y up), the maximum over the
/// whole grid.
pub fn hemisphere(w: usize, h: usize) -> Image<f64> {
    let (cx, cy) = (w.div_ceil(2) as f64, h.div_ceil(2) as f64);
    let d2 = |x: usize, y: usize| {
        let (xx, yy) = ((x + 1) as f64, (h - y) as f64);
        (xx - cx).powi(2) + (yy - cy).powi(2)
    };
    let max = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| d2(x, y))
        .fold(0.0, f64::max);
    Image::from_fn(w, h, |x, y| (max - d2(x, y)).sqrt())
}

/// The previous level's heights `z` (NaN outside its mask) on the grid
/// twice as fine, `w × h` (module doc).
pub fn upsample(z: &Image<f64>, w: usize, h: usize) -> Image<f64> {
    let (pw, ph) = z.size();
    let filled = z.map(|&v| if v.is_nan() { 0.0 } else { v });
    let lo = filled.data().iter().copied().fold(f64::INFINITY, f64::min);
    let lifted = filled.map(|&v| if v < 0.0 { v - lo } else { v });
    let sample = |x: usize, y: usize| -> f64 {
        let (fx, fy) = (x as f64 / 2.0, y as f64 / 2.0);
        if fx > (pw - 1) as f64 || fy > (ph - 1) as f64 {
            return 0.0;
        }
        let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(pw - 1), (y0 + 1).min(ph - 1));
        let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
        let at = |x: usize, y: usize| *lifted.get(x, y);
        (1.0 - ty) * ((1.0 - tx) * at(x0, y0) + tx * at(x1, y0))
            + ty * ((1.0 - tx) * at(x0, y1) + tx * at(x1, y1))
    };
    let mut out = Image::from_fn(w, h, sample);
    if h >= 2 {
        for x in 0..w {
            *out.get_mut(x, h - 1) = *out.get(x, h - 2);
        }
    }
    out
}

/// The normals of heights `z` on `level` through its stencils, as an image
/// of the level's grid (`[0, 0, 0]` outside its mask).
pub fn normals(level: &Level, z: &[f64]) -> Image<[f32; 3]> {
    let values: Vec<[f32; 3]> = (0..level.domain.len())
        .map(|k| {
            let (p, q) = level.gradients.at(k, z);
            let norm = (1.0 + p * p + q * q).sqrt();
            [(-p / norm) as f32, (-q / norm) as f32, (1.0 / norm) as f32]
        })
        .collect();
    level.domain.scatter(&values, [0.0; 3])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hemisphere_of_the_authors_first_level() {
        // 8×8: centre (4, 4) 1-based with y up, i.e. column 3, row 4; the
        // farthest pixel is the top-right corner (x = 8, y = 8), d² = 32.
        let z = hemisphere(8, 8);
        assert!((z.get(3, 4) - 32f64.sqrt()).abs() < 1e-12);
        assert_eq!(*z.get(7, 0), 0.0);
        assert!((z.get(0, 7) - 14f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn upsampling_interpolates_and_repeats_the_last_row() {
        let z = Image::from_fn(3, 3, |x, y| if x == 2 { f64::NAN } else { (x + 3 * y) as f64 });
        let up = upsample(&z, 6, 6);
        assert_eq!(*up.get(0, 0), 0.0);
        assert_eq!(*up.get(2, 2), 4.0);
        assert_eq!(*up.get(1, 0), 0.5);
        // Column 4 sits on the old NaN column (→ 0); column 5 is beyond the
        // samples (→ 0); the last row repeats row 4.
        assert_eq!(*up.get(4, 2), 0.0);
        assert_eq!(*up.get(5, 2), 0.0);
        assert_eq!(up.get(1, 5), up.get(1, 4));
    }
}
