//! The diffuse model of conventions.md §3 fitted to a view's pixels:
//! `I = T(θ)/T(0) · (a + k (n·l̂)⁺ T(θ_i)/T(0))` (`T` the unpolarized
//! Fresnel transmission, `θ_i` the incidence angle, `a` a fill light that
//! enters from everywhere and leaves through `T(θ)`). Steps 2 (`eta`) and 8
//! (`refine`) score refractive indices with its residual; step 2 also fits
//! the light direction with it.
//!
//! Why the direction is fitted here and not taken from the Lambertian light
//! fit (`light`): `I = n·L` has no fill light and no attached shadow, so
//! under a low key light the shadowed side, lit by the fill alone, drags its
//! `L` away from the light. On the path-traced reference views with the key
//! light 30° above the horizon that put the light 15–22° off at 20000 e⁻,
//! and `η` (whose search minimises this residual with that direction) at
//! 1.75 for 1.5 on the sphere; with the true direction the search finds
//! 1.496.

use crate::light::{Lighting, Sample};
use rayon::prelude::*;
use sfp_core::fresnel::unpolarized_transmittance;

/// A sample prepared for fits at one `η`: its intensity, the trigonometry
/// of its zenith and AoP, its exit factor `T(θ)/T(0)` and its weight.
struct Row {
    intensity: f64,
    st: f64,
    ct: f64,
    sp: f64,
    cp: f64,
    out: f64,
    weight: f64,
}

/// Samples prepared for fits of the model at one `η`.
pub(super) struct FresnelSamples {
    rows: Vec<Row>,
    eta: f64,
}

impl FresnelSamples {
    /// `samples` (zeniths at `eta`) with `weights` (`None`: 1 each).
    pub(super) fn new(samples: &[Sample], weights: Option<&[f64]>, eta: f64) -> Self {
        let rows = samples.par_iter().enumerate().map(|(j, s)| {
            let (sp, cp) = s.aop.sin_cos();
            let (st, ct) = s.zenith.sin_cos();
            (s.intensity, st, ct, cp, sp, weights.map_or(1.0, |w| w[j]))
        });
        Self::from_trigonometry(rows, eta)
    }

    /// Samples given as `(intensity, sin θ, cos θ, cos φ, sin φ, weight)`
    /// (`θ` the zenith at `eta`): a caller that holds the trigonometry
    /// passes it instead of angles to take it from again. Prepared in
    /// parallel (a region of a whole object: 667k samples per `η` tried by
    /// step 8).
    pub(super) fn from_trigonometry(
        samples: impl IndexedParallelIterator<Item = (f64, f64, f64, f64, f64, f64)>,
        eta: f64,
    ) -> Self {
        let t0 = transmittance(1.0, eta);
        let rows = samples
            .map(|(intensity, st, ct, cp, sp, weight)| Row {
                intensity,
                st,
                ct,
                sp,
                cp,
                out: transmittance(ct, eta) / t0,
                weight,
            })
            .collect();
        FresnelSamples { rows, eta }
    }

    /// Weighted root-mean-square residual for the light direction `l`
    /// (unit), `a` and `k` by weighted linear least squares alternating with
    /// each sample's choice of candidate normal (± azimuth; the given
    /// azimuth when `fixed_sense`).
    pub(super) fn residual(&self, l: [f64; 3], fixed_sense: bool) -> f64 {
        let t0 = transmittance(1.0, self.eta);
        // Per sample, per candidate: the key-light term (the given sense
        // only when it is fixed).
        let senses: &[f64] = if fixed_sense { &[1.0] } else { &[1.0, -1.0] };
        // The maps run in parallel, the sums in order (results do not
        // depend on the thread count).
        let key: Vec<[f64; 2]> = self
            .rows
            .par_iter()
            .map(|r| {
                let mut f = [0.0; 2];
                for (f, sense) in f.iter_mut().zip(senses) {
                    let cos_i = sense * r.st * (r.cp * l[0] + r.sp * l[1]) + r.ct * l[2];
                    *f = r.out * cos_i.max(0.0) * transmittance(cos_i, self.eta) / t0;
                }
                f
            })
            .collect();
        let weights: f64 = self.rows.iter().map(|r| r.weight).sum();
        let (mut a, mut k) = (0.0, 1.0);
        let mut sse = f64::INFINITY;
        // With the sense fixed nothing alternates: one fit is the answer.
        let passes = if fixed_sense { 1 } else { 10 };
        for _ in 0..passes {
            let chosen: Vec<f64> = self
                .rows
                .par_iter()
                .zip(&key)
                .map(|(r, f)| {
                    let miss = |f: f64| (r.intensity - a * r.out - k * f).abs();
                    if !fixed_sense && miss(f[1]) < miss(f[0]) {
                        f[1]
                    } else {
                        f[0]
                    }
                })
                .collect();
            let (mut soo, mut sof, mut sff, mut sio, mut sif) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for (r, &f) in self.rows.iter().zip(&chosen) {
                let (w, o, i) = (r.weight, r.out, r.intensity);
                soo += w * o * o;
                sof += w * o * f;
                sff += w * f * f;
                sio += w * i * o;
                sif += w * i * f;
            }
            let det = soo * sff - sof * sof;
            if det.abs() <= 1e-12 * soo * sff {
                break;
            }
            a = (sio * sff - sif * sof) / det;
            k = (soo * sif - sof * sio) / det;
            if a < 0.0 {
                // A fill light is not negative: without one, the key alone.
                a = 0.0;
                k = sif / sff;
            }
            let next: f64 = self
                .rows
                .iter()
                .zip(&chosen)
                .map(|(r, &f)| r.weight * (r.intensity - a * r.out - k * f).powi(2))
                .sum();
            let done = (sse - next).abs() <= 1e-12 * next.max(1e-300);
            sse = next;
            if done {
                break;
            }
        }
        (sse / weights.max(1e-300)).sqrt()
    }

    /// The light direction of the upper hemisphere with the smallest
    /// [`residual`](Self::residual), by a pattern search on its azimuth and
    /// elevation from `start` (steps from 8° down to 0.1°; a 2-parameter
    /// problem with one smooth minimum near a good start).
    pub(super) fn direction(&self, start: [f64; 3]) -> [f64; 3] {
        let half_pi = std::f64::consts::FRAC_PI_2;
        let unit = |az: f64, el: f64| [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
        let (mut az, mut el) = (start[1].atan2(start[0]), start[2].clamp(0.0, 1.0).asin());
        let mut best = self.residual(unit(az, el), false);
        let mut step = 8f64.to_radians();
        while step > 0.1f64.to_radians() {
            // An azimuth step of `step` moves the direction by `step` at any
            // elevation.
            let da = step / el.cos().max(0.05);
            let moves = [(da, 0.0), (-da, 0.0), (0.0, step), (0.0, -step)];
            let tried: Vec<(f64, f64, f64)> = moves
                .par_iter()
                .map(|&(da, de)| {
                    let (a, e) = (az + da, (el + de).clamp(0.0, half_pi));
                    (a, e, self.residual(unit(a, e), false))
                })
                .collect();
            let better = tried
                .into_iter()
                .filter(|t| t.2 < best)
                .min_by(|x, y| x.2.total_cmp(&y.2));
            match better {
                Some((a, e, r)) => (az, el, best) = (a, e, r),
                None => step /= 2.0,
            }
        }
        unit(az, el)
    }
}

/// RMS residual of the model with the light direction of `lighting`, `a`
/// and `k` fitted ([`FresnelSamples::residual`]).
pub(super) fn fresnel_residual(
    samples: &[Sample],
    lighting: &Lighting,
    eta: f64,
    fixed_sense: bool,
) -> f64 {
    FresnelSamples::new(samples, None, eta).residual(lighting.direction(), fixed_sense)
}

/// Unpolarized Fresnel transmission at incidence cosine `c` (clamped to
/// [0, 1]).
fn transmittance(c: f64, eta: f64) -> f64 {
    unpolarized_transmittance(c.clamp(0.0, 1.0), eta)
}
