//! The surface fit under the mixed reflection model (issue: glossy objects,
//! item 2): heights whose normals, with each pixel's specular share,
//! explain the measured normalised Stokes vectors `(s1, s2)/s0`.
//!
//! A per-pixel reading cannot do this: with the share free, one pixel's
//! polarization allows a diffuse zenith and two specular ones, at azimuths
//! 90° apart (`core::oracle`). Tying the pixels together decides between
//! them: the normals must come from one height field, and the share of `s0`
//! the surface reflects changes slowly across a material.
//!
//! The fit alternates two steps from a starting surface (SMSfP's):
//! 1. **Shares.** Under the current normals the share that explains a
//!    pixel's polarization along its azimuth is `f = (ρ_d − q)/(ρ_d + ρ_s)`
//!    (`share`), known to the precision `(ρ_d + ρ_s)² / σ²`; each pixel takes
//!    the precision-weighted mean over a window of [`SHARE_RADIUS`], clamped
//!    to `[0, 1]` (materials are piecewise smooth).
//! 2. **Heights.** One Levenberg–Marquardt step of the residuals
//!    `(v − m(∇z)) / σ` (`mixture`), each pixel's `σ²` the Stokes noise of
//!    its `s0` (`noise`) plus [`MODEL_SIGMA`]², linearised at the current
//!    gradient: rows over `z` on the shared sparse solver, with a damping
//!    row on each gradient and a weak Laplacian ([`SMOOTHNESS`]) where data
//!    vanish (a surface facing the camera is unpolarized). A step that
//!    raises the cost is retried with more damping.
//!
//! The model is even in the gradient, so the fit keeps each pixel's sense
//! from the start; which of the 90°-apart azimuths holds, it decides. It
//! stops when the cost falls by less than [`TOLERANCE`] of itself, or after
//! [`MAX_ITERATIONS`] (`converged: false`).

use crate::input::Input;
use crate::noise::StokesNoise;
use crate::solver::domain::Domain;
use crate::solver::lsq::{NormalEquations, Solver};
use crate::solver::operators::{Operators, Stencil};
use crate::solver::ordering::Ordering;
use crate::specular::mixture::{Mixture, dops};
use crate::specular::share::share_along;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sfp_core::integral::Integral;
use sfp_core::{Error, Image, Mask, NormalMap, Result};

/// Model error of a normalised Stokes component: roughness, interreflection
/// and the light's own polarization, none of which the model holds.
pub const MODEL_SIGMA: f64 = 0.02;
/// Half-width of the window a pixel's share is averaged over.
pub const SHARE_RADIUS: usize = 3;
/// Weight of the Laplacian rows relative to a data row of [`MODEL_SIGMA`].
pub const SMOOTHNESS: f64 = 0.03;
/// Relative fall of the cost below which the fit has converged.
pub const TOLERANCE: f64 = 1e-3;
pub const MAX_ITERATIONS: usize = 60;
/// Damping of the first step, relative to a data row of [`MODEL_SIGMA`].
const FIRST_DAMPING: f64 = 0.1;
/// Damping beyond which a step that does not lower the cost ends the fit
/// (converged: no step in any direction lowers it).
const MAX_DAMPING: f64 = 1e4;

/// The refractive index of most dielectrics (plastics, glass, fruit skin
/// between water's 1.33 and glass's 1.7), which Smith et al. 2019 and Yu
/// et al. 2017 fix for their fits.
pub const TYPICAL_ETA: f64 = 1.5;

/// The refractive index the fit reads the polarization at: `given` when
/// the method took the user's index as it is (`estimated` false), else
/// [`TYPICAL_ETA`]. Estimates under the diffuse model are no estimates on
/// a glossy surface: they read the strong specular polarization as a high
/// index (SMSfP's search on the glossy preset: 1.7–2.5 for true 1.4–1.7,
/// 12 of 22 views at its range's end, 2.5; the fit's mean MAE there 26.24°
/// at the search's index, 24.35° at 1.5).
pub fn reading_eta(estimated: bool, given: f64) -> f64 {
    if estimated { TYPICAL_ETA } else { given }
}

/// What the fit did (`run.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    pub eta: f64,
    pub iterations: usize,
    pub converged: bool,
    /// Cost (squared weighted residuals and smoothness rows) per mask
    /// pixel, at the start and at the end.
    pub cost_start: f64,
    pub cost_end: f64,
    /// Share of the fitted pixels whose residual exceeds three of its `σ`:
    /// what the model leaves unexplained.
    pub unexplained: f64,
}

/// Share of the fitted pixels left unexplained above which the fit warns.
pub const WARN_UNEXPLAINED: f64 = 0.05;

impl FitRecord {
    /// What `run.json` and stderr should say about the fit, with what to do.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.converged {
            out.push(format!(
                "the mixed-model fit did not converge in {} iterations (cost per pixel {:.3} \
                 from {:.3}; run.json: fit): its normals are those of the last step",
                self.iterations, self.cost_end, self.cost_start
            ));
        }
        if self.unexplained > WARN_UNEXPLAINED {
            out.push(format!(
                "the mixed model leaves {:.0}% of the mask unexplained (residual beyond 3σ; \
                 run.json: fit.unexplained): interreflections, a polarized light or a wrong \
                 refractive index (η {:.2}; give it with --set refine=false --eta N)",
                100.0 * self.unexplained,
                self.eta
            ));
        }
        out
    }
}

/// The fitted surface.
pub struct SurfaceFit {
    pub normals: NormalMap,
    /// NaN outside the mask.
    pub height: Image<f32>,
    /// Each mask pixel's specular share of `s0`; 0 outside.
    pub share: Image<f32>,
    pub record: FitRecord,
}

/// The data of one unknown.
#[derive(Clone, Copy)]
struct Pixel {
    /// Measured `(s1, s2) / s0`.
    v: [f64; 2],
    /// `1/σ`, 0 where the data are unusable.
    weight: f64,
    dx: Option<Stencil>,
    dy: Option<Stencil>,
    laplacian: Option<Stencil>,
}

/// Fits heights to `input`'s measured polarization (AoPs as measured, not
/// turned by a labelling) from the heights `start` (NaN where unknown),
/// at refractive index `eta`, with the Stokes noise `noise`.
pub fn fit(input: &Input, start: &Image<f32>, eta: f64, noise: &StokesNoise) -> Result<SurfaceFit> {
    if !start.same_size(&input.mask) {
        return Err(Error::invalid("starting heights and mask differ in size"));
    }
    let mask = Mask::from_fn(input.mask.width(), input.mask.height(), |x, y| {
        *input.mask.get(x, y) && start.get(x, y).is_finite()
    });
    let domain = Domain::new(&mask);
    let pixels = pixels(input, &domain, noise);
    let mut z: Vec<f64> = domain.gather(start).into_iter().map(f64::from).collect();
    let mut solver = Solver::new(Ordering::default());
    let mut damping = FIRST_DAMPING;
    let mut share = shares(&domain, &pixels, &z, eta);
    let cost_start = cost(&pixels, &z, &share, eta);
    let mut current = cost_start;
    let (mut iterations, mut converged) = (0, false);
    while iterations < MAX_ITERATIONS && !converged {
        iterations += 1;
        let before = current;
        loop {
            let next = step(&domain, &pixels, &z, &share, eta, damping, &mut solver)?;
            let c = cost(&pixels, &next, &share, eta);
            if c < current {
                z = next;
                damping = (damping / 3.0).max(1e-6);
                break;
            }
            damping *= 4.0;
            if damping > MAX_DAMPING {
                break;
            }
        }
        share = shares(&domain, &pixels, &z, eta);
        current = cost(&pixels, &z, &share, eta);
        converged = before - current <= TOLERANCE * before || damping > MAX_DAMPING;
    }
    let n = domain.len().max(1) as f64;
    let record = FitRecord {
        eta,
        iterations,
        converged,
        cost_start: cost_start / n,
        cost_end: current / n,
        unexplained: unexplained(&pixels, &z, &share, eta),
    };
    let normals = crate::solver::integrate::normals_of(&domain, &z);
    let heights: Vec<f32> = z.iter().map(|&v| v as f32).collect();
    let shares: Vec<f32> = share.iter().map(|&v| v as f32).collect();
    Ok(SurfaceFit {
        normals: domain.scatter(&normals, [0.0; 3]),
        height: domain.scatter(&heights, f32::NAN),
        share: domain.scatter(&shares, 0.0),
        record,
    })
}

/// Each unknown's data and stencils.
fn pixels(input: &Input, domain: &Domain, noise: &StokesNoise) -> Vec<Pixel> {
    let ops = Operators::new(domain);
    (0..domain.len())
        .into_par_iter()
        .map(|k| {
            let (x, y) = domain.pixel(k);
            let rho = f64::from(*input.dop.get(x, y));
            let psi = f64::from(*input.aop.get(x, y));
            let s0 = 2.0 * f64::from(*input.intensity.get(x, y));
            let usable = !*input.unlit.get(x, y) && !*input.saturated.get(x, y) && s0 > 0.0;
            let sigma2 = noise.dop_sigma(s0).powi(2) + MODEL_SIGMA * MODEL_SIGMA;
            Pixel {
                v: [rho * (2.0 * psi).cos(), rho * (2.0 * psi).sin()],
                weight: if usable { sigma2.sqrt().recip() } else { 0.0 },
                dx: ops.dx(k),
                dy: ops.dy(k),
                laplacian: ops.laplacian(k),
            }
        })
        .collect()
}

/// The gradient at a pixel; `None` without both derivatives.
fn gradient(pixel: &Pixel, z: &[f64]) -> Option<(f64, f64)> {
    Some((pixel.dx?.apply(z), pixel.dy?.apply(z)))
}

/// Weighted squared residual of every pixel.
fn residuals<'a>(
    pixels: &'a [Pixel],
    z: &'a [f64],
    share: &'a [f64],
    eta: f64,
) -> impl ParallelIterator<Item = f64> + 'a {
    pixels.par_iter().zip(share).map(move |(px, &f)| {
        let Some((p, q)) = gradient(px, z) else {
            return 0.0;
        };
        let m = Mixture { share: f, eta }.at(p, q).value;
        let (a, b) = (px.v[0] - m[0], px.v[1] - m[1]);
        px.weight * px.weight * (a * a + b * b)
    })
}

/// The cost the steps lower: the squared weighted residuals and the
/// smoothness rows.
fn cost(pixels: &[Pixel], z: &[f64], share: &[f64], eta: f64) -> f64 {
    let smooth = SMOOTHNESS / MODEL_SIGMA;
    let roughness: f64 = pixels
        .par_iter()
        .filter_map(|px| px.laplacian.map(|l| (smooth * l.apply(z)).powi(2)))
        .sum();
    residuals(pixels, z, share, eta).sum::<f64>() + roughness
}

/// Share of the usable pixels with a residual beyond 3σ (two components:
/// `χ²₂ > 9` for a unit Gaussian has probability 1.1%).
fn unexplained(pixels: &[Pixel], z: &[f64], share: &[f64], eta: f64) -> f64 {
    let usable = pixels.iter().filter(|p| p.weight > 0.0).count();
    let beyond = residuals(pixels, z, share, eta)
        .filter(|&r| r > 9.0)
        .count();
    beyond as f64 / usable.max(1) as f64
}

/// Step 1 of the module doc: every unknown's share under heights `z`.
fn shares(domain: &Domain, pixels: &[Pixel], z: &[f64], eta: f64) -> Vec<f64> {
    let (w, h) = domain.size();
    let mut evidence = vec![[0.0f64; 2]; w * h];
    let reading: Vec<(usize, [f64; 2])> = pixels
        .par_iter()
        .enumerate()
        .map(|(k, px)| {
            let (x, y) = domain.pixel(k);
            let e = gradient(px, z).and_then(|(p, q)| {
                let (d, s) = dops(p, q, eta);
                let u = p * p + q * q;
                // Polarization along the azimuth: v · (cos 2φ, sin 2φ).
                let along = (px.v[0] * (p * p - q * q) + px.v[1] * 2.0 * p * q) / u;
                let f = share_along(along, d, s)?;
                let precision = (d + s).powi(2) * px.weight * px.weight;
                Some([precision * f, precision])
            });
            (y * w + x, e.unwrap_or([0.0; 2]))
        })
        .collect();
    for (i, e) in reading {
        evidence[i] = e;
    }
    let sums = Integral::new(w, h, |i| evidence[i]);
    (0..domain.len())
        .into_par_iter()
        .map(|k| {
            let (x, y) = domain.pixel(k);
            let [weighted, precision] = sums.window(x, y, SHARE_RADIUS);
            if precision > 0.0 {
                (weighted / precision).clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
        .collect()
}

/// Step 2 of the module doc: the heights after one damped Gauss–Newton
/// step from `z` with shares `share` and damping `damping`.
fn step(
    domain: &Domain,
    pixels: &[Pixel],
    z: &[f64],
    share: &[f64],
    eta: f64,
    damping: f64,
    solver: &mut Solver,
) -> Result<Vec<f64>> {
    let scale = MODEL_SIGMA.recip();
    let mut eq = NormalEquations::new(domain);
    for (px, &f) in pixels.iter().zip(share) {
        if let Some(lap) = px.laplacian {
            eq.add(&lap, 0.0, SMOOTHNESS / MODEL_SIGMA);
        }
        let (Some(dx), Some(dy)) = (px.dx, px.dy) else {
            continue;
        };
        let (p, q) = (dx.apply(z), dy.apply(z));
        let model = Mixture { share: f, eta }.at(p, q);
        if px.weight > 0.0 {
            for (i, j) in model.jacobian.iter().enumerate() {
                let row = dx.combine(j[0], &dy, j[1]);
                let value = px.v[i] - model.value[i] + j[0] * p + j[1] * q;
                eq.add(&row, value, px.weight);
            }
        }
        let d = damping.sqrt() * scale;
        eq.add(&dx, p, d);
        eq.add(&dy, q, d);
    }
    let solution = solver.solve(&eq)?;
    Ok(solution.z.into_iter().next().unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::stokes_noise;
    use crate::solver::integrate::{height_from_normals, normals_from_height};
    use crate::test_support::{analytic, mixture};
    use sfp_core::analytic::Shape;
    use sfp_core::metrics::evaluate;

    /// Mean angular error of `normals` against `gt` over `mask`, degrees.
    fn mae(normals: &NormalMap, gt: &NormalMap, mask: &Mask) -> f64 {
        evaluate(normals, gt, mask).unwrap().mae_deg
    }

    /// Heights of `gt` with every normal's zenith scaled by `factor`: a
    /// start of the right shape but wrong depth.
    fn flattened(gt: &NormalMap, mask: &Mask, factor: f32) -> Image<f32> {
        let squashed = gt.map(|n| {
            if n[2] <= 0.0 {
                return *n;
            }
            let theta = n[2].min(1.0).acos() * factor;
            let r = (n[0] * n[0] + n[1] * n[1]).sqrt().max(1e-12);
            [n[0] / r * theta.sin(), n[1] / r * theta.sin(), theta.cos()]
        });
        height_from_normals(&squashed, mask).unwrap()
    }

    /// The fit of `input` at η 1.5 from heights `start`: the MAE of the
    /// start and of the fit against `gt`, and the fit.
    fn fitted(
        label: &str,
        input: &Input,
        gt: &NormalMap,
        start: &Image<f32>,
    ) -> (f64, f64, SurfaceFit) {
        let fit = fit(input, start, 1.5, &stokes_noise(input)).unwrap();
        let start_normals = normals_from_height(start, &input.mask);
        let before = mae(&start_normals, gt, &input.mask);
        let after = mae(&fit.normals, gt, &input.mask);
        println!("{label}: {before:.2}° → {after:.2}°, {:?}", fit.record);
        (before, after, fit)
    }

    #[test]
    fn a_diffuse_sphere_is_recovered_from_a_flattened_start() {
        let (input, gt) = analytic(Shape::Sphere, 64, 1.5);
        let start = flattened(&gt, &input.mask, 0.6);
        let (before, after, fit) = fitted("diffuse sphere", &input, &gt, &start);
        assert!(after < 3.0 && after < before / 3.0, "{before}° → {after}°");
        let share = fit.share.data().iter().copied().fold(0.0f32, f32::max);
        assert!(share < 0.05, "a diffuse sphere read {share} specular");
        assert!(fit.record.converged && fit.record.warnings().is_empty());
        let stuck = FitRecord {
            converged: false,
            unexplained: 0.2,
            ..fit.record
        };
        let said = stuck.warnings().join("\n");
        assert!(
            said.contains("did not converge") && said.contains("20% of the mask"),
            "{said}"
        );
    }

    #[test]
    fn a_mixture_with_turned_azimuths_is_recovered() {
        // Left half 20% specular, right half 70%: most AoPs are turned by
        // 90° (the specular part outweighs the diffuse one).
        let (input, gt) = mixture(1.5, |x| if x < 32 { 0.2 } else { 0.7 });
        let start = flattened(&gt, &input.mask, 0.85);
        let (before, after, fit) = fitted("mixture sphere", &input, &gt, &start);
        assert!(after < 4.0 && after < before / 2.0, "{before}° → {after}°");
        let at = |x, y| f64::from(*fit.share.get(x, y));
        assert!((at(16, 40) - 0.2).abs() < 0.1 && (at(48, 40) - 0.7).abs() < 0.1);
    }
}
