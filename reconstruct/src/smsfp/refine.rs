//! Step 8 of SMSfP (module doc): refinement of `η` and the relative albedo
//! `α` per region (Eq. 19), re-solving.
//!
//! Per region, `η` is fitted within `eta_band` of the whole object's by
//! least squares on the shading law of step 2 (the region's normals
//! `n(θ(ρ, η), φ)`, `φ` the AoP in the sense of the solved surface, against
//! `I_un`, with the object's light), and the relative albedo `α` between
//! `I_un` and the Lambertian shading `n·L`; `θ` is recomputed (Eq. 7), the
//! rows rebuilt and the region re-solved until the RMS height change falls
//! below `tolerance` of the RMS height, `η` and `α` both move by less than
//! [`PARAMETER_STEP`], or `max_iterations` solves. The light's magnitude
//! carries the albedo × irradiance, so `α` is relative to the whole object
//! (1 = the object's mean). Eq. 19 as printed compares `ρ` with
//! `ρ_d(θ(z), η)`; the solved zenith is smoothed by the integration, so that
//! fit raised `η` at every pass (built-in views: 1.44 → 1.55–2.5 over three
//! passes). Unbounded, the per-region fit followed the misfits of large
//! complex regions (preset-a camera body: 1.24 for 1.5, 21.9° → 27.6° MAE;
//! preset-a mean 16.7° unbounded, 14.9° within ±0.2, 13.7° within ±0.05,
//! where b and builtin gain too: 7.6° and 5.4°).

use super::azimuth::azimuth_in_sense;
use super::eta::{ETA_SEARCH, ShadingLaw, around, eta_grid, golden_min};
use super::fresnel_fit::FresnelSamples;
use super::region::RegionState;
use super::solve::solve_region;
use crate::light::Lighting;
use rayon::prelude::*;
use sfp_core::Result;
use sfp_core::fresnel::diffuse_zenith_sin_cos;

/// Refinement stops without another solve when `η` and `α` move less.
const PARAMETER_STEP: f64 = 0.005;

/// Pixels a region needs for the `η`/`α` fit.
const MIN_FIT_PIXELS: usize = 200;

/// The refinement's parameters (`Smsfp::eta_band`, `max_iterations`,
/// `tolerance`, `lambda`) and the shading law step 2 chose.
pub(super) struct Refinement {
    /// A region's `η` stays within this of the whole object's.
    pub eta_band: f64,
    /// Solves per region, the first included.
    pub max_iterations: usize,
    /// Relative RMS height change below which a region has converged.
    pub tolerance: f64,
    /// Laplacian smoothness weight of the re-solves.
    pub lambda: f64,
    pub model: ShadingLaw,
}

impl Refinement {
    /// Refines every region with the object's `lighting`, in parallel.
    pub(super) fn refine(&self, states: &mut [RegionState], lighting: &Lighting) -> Result<()> {
        states
            .par_iter_mut()
            .try_for_each(|s| self.refine_region(s, lighting))
    }

    /// The refinement of one region (module doc).
    fn refine_region(&self, s: &mut RegionState, lighting: &Lighting) -> Result<()> {
        while s.iterations < self.max_iterations {
            let band = self.eta_band;
            let range = (
                (s.eta0 - band).max(ETA_SEARCH.0),
                (s.eta0 + band).min(ETA_SEARCH.1),
            );
            let Some((eta, alpha)) = fit_eta_alpha(s, lighting, range, self.model) else {
                break;
            };
            // The rows would be the same to a few parts in a thousand.
            if (eta - s.eta).abs() < PARAMETER_STEP && (alpha - s.alpha).abs() < PARAMETER_STEP {
                s.converged = true;
                break;
            }
            s.eta = eta;
            s.alpha = alpha;
            let previous = std::mem::take(&mut s.z);
            solve_region(s, lighting, false, self.lambda)?;
            let kept = s.solved.take().expect("solved").candidates.swap_remove(0);
            s.z = kept.z;
            s.normals = kept.normals;
            let (mut change, mut size) = (0.0, 0.0);
            for (a, b) in s.z.iter().zip(&previous) {
                change += (a - b) * (a - b);
                size += a * a;
            }
            if change <= self.tolerance * self.tolerance * size.max(1e-300) {
                s.converged = true;
                break;
            }
        }
        Ok(())
    }
}

/// Eq. 19 for one region (module doc): `η` in `range` minimising
/// the residual of the shading law `model` over the region's lit pixels
/// whose DoP is measured, the normals `n(θ(ρ, η), φ)` with `φ` the AoP in
/// the sense of the solved surface's normal and the whole object's light
/// (on a 0.05 grid, then by golden section); and the relative albedo `α`
/// minimising `Σ (I_un − α n·L)²` at that `η`. `None` with too few pixels.
fn fit_eta_alpha(
    s: &RegionState,
    lighting: &Lighting,
    range: (f64, f64),
    model: ShadingLaw,
) -> Option<(f64, f64)> {
    // (intensity, ρ, cos φ, sin φ) per usable pixel.
    let mut pixels = Vec::new();
    for (k, n) in s.normals.iter().enumerate() {
        let (x, y) = s.domain.pixel(k);
        if *s.input.dark.get(x, y) || !*s.measured.get(x, y) {
            continue;
        }
        let (cp, sp) = azimuth_in_sense(f64::from(*s.input.aop.get(x, y)), n);
        pixels.push((
            f64::from(*s.input.intensity.get(x, y)) / s.input.intensity_scale,
            f64::from(*s.input.dop.get(x, y)),
            cp,
            sp,
        ));
    }
    if pixels.len() < MIN_FIT_PIXELS {
        return None;
    }
    let [lx, ly, lz] = lighting.vector;
    // Best α for `eta` and the residual sum of squares with it (the
    // shading in parallel, the sums in order).
    let fit = |eta: f64| {
        let shading: Vec<f64> = pixels
            .par_iter()
            .map(|&(_, rho, c, s)| {
                let (st, ct) = diffuse_zenith_sin_cos(rho, eta);
                lighting.ambient + st * (c * lx + s * ly) + ct * lz
            })
            .collect();
        let (mut num, mut den, mut ii) = (0.0, 0.0, 0.0);
        for (&(i, ..), &shade) in pixels.iter().zip(&shading) {
            num += i * shade;
            den += shade * shade;
            ii += i * i;
        }
        if den <= 0.0 {
            return (1.0, f64::INFINITY);
        }
        (num / den, ii - num * num / den)
    };
    let criterion = |eta: f64| match model {
        ShadingLaw::Fresnel => {
            let samples = pixels.par_iter().map(|&(i, rho, c, s)| {
                let (st, ct) = diffuse_zenith_sin_cos(rho, eta);
                (i, st, ct, c, s, 1.0)
            });
            FresnelSamples::from_trigonometry(samples, eta).residual(lighting.direction(), true)
        }
        ShadingLaw::Lambert => fit(eta).1,
    };
    let (grid, step) = eta_grid(range);
    let best = grid
        .into_iter()
        .map(|e| (e, criterion(e)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("non-empty grid")
        .0;
    let (lo, hi) = around(best, step, range);
    let eta = golden_min(lo, hi, 20, criterion);
    let (alpha, _) = fit(eta);
    (alpha > 0.0 && alpha.is_finite()).then_some((eta, alpha))
}
