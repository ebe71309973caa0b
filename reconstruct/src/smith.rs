//! Smith, Ramamoorthi, Tozza: "Linear depth estimation from an uncalibrated,
//! monocular polarisation image" (ECCV 2016) and "Height-from-polarisation
//! with unknown lighting or albedo" (TPAMI 2019) — the baseline SMSfP builds
//! on (SMSfP paper §4.1–4.4).
//!
//! Unknown: the height `z` over the mask. One linear least-squares problem
//! (`lsq`) with, per pixel:
//! 1. **azimuth** (phase) constraint, conventions.md §3 (corrected form of
//!    the paper's Eqs. 8–9): `sin ψ · z_x − cos ψ · z_y = 0`, weight 1;
//! 2. **shading/polarization ratio** (paper Eq. 12 with `v = [0, 0, 1]`,
//!    albedo folded into the light, `I_un = a + n · L`; with an albedo map
//!    `α(x)` given, `I_un / α` is used instead, so `L` is the irradiance):
//!    `cos θ (L_x z_x + L_y z_y) = cos θ L_z − (I_un − a)`, weight 1,
//!    intensities divided by the robust maximum so both rows are O(1);
//! 3. **boundary convexity prior** (`prior`), weight `w` (1 on the contour,
//!    `(1 − d/d_max)^5` inside): `cos θ z_x = −sin θ cos φ_prior`,
//!    `cos θ z_y = −sin θ sin φ_prior`;
//! 4. **Laplacian smoothness** `∇²z = 0` with weight `λ` at pixels whose
//!    4 neighbours are inside.
//!
//! Derivatives are the smoothed central differences of `operators`; the
//! normals reported are those of the solved height through the same stencils.
//!
//! Parameters (defaults): `η = 1.5` (Smith's code), `λ = 0.1`, prior exponent
//! 5, light estimated (point source) with seed 0, nested-dissection ordering.
//!
//! Choices the papers leave open or get wrong, made here:
//! - `ρ` above the model maximum (≈ 0.384 at η = 1.5) is clamped before the
//!   closed-form inverse (counted in `run.json`);
//! - dark pixels (`I_un` below 3 % of the robust maximum, `input`) carry no
//!   shading row but keep the other constraints;
//! - unlit pixels (`I_un` ≤ 0.5 % of the robust maximum: attached or cast
//!   shadow) have no measurable DoP or AoP, so no azimuth row either, and the
//!   prior enters there as a direction-only row
//!   `sin φ_prior z_x − cos φ_prior z_y = 0` (weight `w`). Feeding their
//!   DoP of 0 (θ = 0) to the prior rows flattens the shadowed rim: 20° mean
//!   error on the outer tenth of the analytic sphere instead of 3°;
//! - pixels without a neighbour along x or along y carry no gradient rows
//!   (they still get a height through the Laplacian of their neighbours or,
//!   if isolated, height 0);
//! - with estimated light, the convex/concave pair `L`, `(−L_x, −L_y, L_z)`
//!   are both solved and the one whose normals agree better with the
//!   outward contour normals in a band along the boundary is kept (never the
//!   "larger volume" rule); both scores are recorded. The band is a quarter
//!   of the largest boundary distance wide: closer to the contour the prior
//!   rows make both candidates look convex. Flipping the light only negates
//!   the shading rows, so `CᵀC` is shared: one factorisation, two solves.

use crate::domain::Domain;
use crate::input::Input;
use crate::integrate::normals_of;
use crate::light::{LightEstimate, LightModel, Lighting, Sample, estimate};
use crate::lsq::{NormalEquations, Solver};
use crate::method::{Method, Reconstruction};
use crate::operators::Operators;
use crate::ordering::Ordering;
use crate::prior::{ConvexityPrior, DEFAULT_EXPONENT, convexity_prior};
use serde_json::json;
use sfp_core::{Error, Image, Result};
use std::time::Instant;

/// How Smith's method obtains the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightSource {
    /// Estimate an unknown point source from the polarization image.
    Estimate,
    /// Estimate first-order spherical-harmonic lighting (ambient + directional).
    EstimateAmbient,
    /// Known direction (towards the light, camera frame), unknown intensity.
    Direction([f64; 3]),
}

/// The Smith et al. baseline with its parameters.
#[derive(Clone, Debug)]
pub struct Smith {
    pub eta: f64,
    /// Laplacian smoothness weight `λ`.
    pub lambda: f64,
    pub light: LightSource,
    pub prior_exponent: f64,
    /// Seed of the light estimator's starting lights.
    pub seed: u64,
    pub ordering: Ordering,
    /// Per-pixel albedo, when known; `None` folds a constant albedo into the
    /// light. Pixels with albedo ≤ 0 carry no shading row.
    pub albedo: Option<Image<f32>>,
}

impl Default for Smith {
    fn default() -> Self {
        Smith {
            eta: 1.5,
            lambda: 0.1,
            light: LightSource::Estimate,
            prior_exponent: DEFAULT_EXPONENT,
            seed: 0,
            ordering: Ordering::default(),
            albedo: None,
        }
    }
}

/// The boundary band that decides between light candidates reaches this
/// fraction of the largest boundary distance inwards, and at least
/// `BAND_MIN` pixels.
const BAND_FRACTION: f32 = 0.25;
const BAND_MIN: f32 = 3.0;

/// Per-pixel data the rows are built from, in unknown order.
struct Pixels {
    theta: Vec<f64>,
    aop: Vec<f64>,
    /// `I_un` divided by the robust maximum.
    intensity: Vec<f64>,
    dark: Vec<bool>,
    unlit: Vec<bool>,
}

impl Method for Smith {
    fn name(&self) -> &str {
        "smith"
    }

    fn reconstruct(&self, input: &Input) -> Result<Reconstruction> {
        self.validate()?;
        let total = Instant::now();
        let domain = Domain::new(&input.mask);
        // The symbolic factorisation depends on the mask only: it runs on
        // another thread while the prior, light and rows are computed.
        std::thread::scope(|scope| {
            let solver = scope.spawn(|| {
                let mut solver = Solver::new(self.ordering);
                solver.prepare(&domain).map(|()| solver)
            });
            let (theta, clamped) = input.zenith(self.eta);
            let mut pixels = Pixels {
                theta: domain.gather(&theta).into_iter().map(f64::from).collect(),
                aop: domain
                    .gather(&input.aop)
                    .into_iter()
                    .map(f64::from)
                    .collect(),
                intensity: domain
                    .gather(&input.intensity)
                    .into_iter()
                    .map(|v| f64::from(v) / input.intensity_scale)
                    .collect(),
                dark: domain.gather(&input.dark),
                unlit: domain.gather(&input.unlit),
            };
            if let Some(albedo) = &self.albedo {
                if !albedo.same_size(&input.mask) {
                    return Err(Error::invalid("albedo map and input differ in size"));
                }
                for (k, a) in domain.gather(albedo).into_iter().enumerate() {
                    if a > 0.0 && a.is_finite() {
                        pixels.intensity[k] /= f64::from(a);
                    } else {
                        pixels.dark[k] = true;
                    }
                }
            }

            let start = Instant::now();
            let prior = convexity_prior(&input.mask, self.prior_exponent);
            let seconds_prior = start.elapsed().as_secs_f64();

            let start = Instant::now();
            let estimate = self.estimate_light(&pixels)?;
            let seconds_light = start.elapsed().as_secs_f64();
            let candidates = match self.light {
                LightSource::Direction(_) => vec![estimate.lighting],
                _ => vec![estimate.lighting, estimate.lighting.flipped()],
            };

            // One system, one right-hand side per light candidate: the flipped
            // light negates the shading rows' coefficients, which leaves CᵀC
            // unchanged and negates their right-hand side instead.
            let start = Instant::now();
            let mut eq = NormalEquations::with_right_hand_sides(&domain, candidates.len());
            self.add_base_rows(&mut eq, &pixels, &prior);
            let shading_rows =
                add_shading_rows(&mut eq, &pixels, &estimate.lighting, candidates.len());
            let seconds_assembly = start.elapsed().as_secs_f64();
            let mut solver = solver
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
            let mut solution = solver.solve(&eq)?;
            let mut results: Vec<(Vec<[f32; 3]>, f64)> = solution
                .z
                .iter()
                .map(|z| {
                    let normals = normals_of(&domain, z);
                    let score = boundary_agreement(&domain, &normals, &prior);
                    (normals, score)
                })
                .collect();
            // The estimate itself unless its partner agrees strictly better.
            let chosen = usize::from(results.len() == 2 && results[1].1 > results[0].1);
            let light_json: Vec<_> = candidates
                .iter()
                .zip(&results)
                .map(|(l, r)| {
                    json!({
                        "vector": l.vector,
                        "direction": l.direction(),
                        "ambient": l.ambient,
                        "boundary_agreement": r.1,
                    })
                })
                .collect();
            let (normals, _) = results.swap_remove(chosen);
            let height: Vec<f32> = solution
                .z
                .swap_remove(chosen)
                .iter()
                .map(|&v| v as f32)
                .collect();
            let rows = eq.rows();
            let (seconds_symbolic, seconds_numeric) =
                (solution.seconds_symbolic, solution.seconds_numeric);
            let run = json!({
                "method": self.name(),
                "parameters": {
                    "eta": self.eta,
                    "lambda": self.lambda,
                    "light": self.light_json(),
                    "prior_exponent": self.prior_exponent,
                    "seed": self.seed,
                    "ordering": self.ordering.name(),
                    "albedo_map": self.albedo.is_some(),
                },
                "light": {
                    "candidates": light_json,
                    "chosen": chosen,
                    "rms_residual": estimate.rms_residual,
                    "iterations": estimate.iterations,
                    "starts": estimate.starts,
                    "intensity_scale": input.intensity_scale,
                },
                "counts": {
                    "pixels": domain.len(),
                    "rows": rows,
                    "shading_rows": shading_rows,
                    "dark_pixels": input.dark.count(),
                    "unlit_pixels": input.unlit.count(),
                    "dop_clamped": clamped,
                    "nonfinite_dropped": input.dropped_nonfinite,
                    "components": solution.components,
                    "symbolic_reused": solution.symbolic_reused,
                },
                "timings": {
                    "prior": seconds_prior,
                    "light": seconds_light,
                    "assembly": seconds_assembly,
                    "solve_symbolic": seconds_symbolic,
                    "solve_numeric": seconds_numeric,
                    "solve": seconds_symbolic + seconds_numeric,
                    "total": total.elapsed().as_secs_f64(),
                },
            });
            Ok(Reconstruction {
                normals: domain.scatter(&normals, [0.0; 3]),
                height: domain.scatter(&height, f32::NAN),
                run,
            })
        })
    }
}

impl Smith {
    fn validate(&self) -> Result<()> {
        if !(self.eta > 1.0 && self.eta.is_finite()) {
            return Err(Error::invalid(format!(
                "eta {} must be a finite number > 1",
                self.eta
            )));
        }
        if !(self.lambda >= 0.0 && self.lambda.is_finite()) {
            return Err(Error::invalid(format!(
                "lambda {} must be ≥ 0",
                self.lambda
            )));
        }
        if !(self.prior_exponent > 0.0 && self.prior_exponent.is_finite()) {
            return Err(Error::invalid(format!(
                "prior exponent {} must be > 0",
                self.prior_exponent
            )));
        }
        Ok(())
    }

    fn light_json(&self) -> serde_json::Value {
        match self.light {
            LightSource::Estimate => json!("estimate"),
            LightSource::EstimateAmbient => json!("estimate_ambient"),
            LightSource::Direction(d) => json!({ "direction": d }),
        }
    }

    fn estimate_light(&self, pixels: &Pixels) -> Result<LightEstimate> {
        let samples: Vec<Sample> = (0..pixels.theta.len())
            .filter(|&k| !pixels.dark[k])
            .map(|k| Sample {
                intensity: pixels.intensity[k],
                zenith: pixels.theta[k],
                aop: pixels.aop[k],
            })
            .collect();
        let model = match self.light {
            LightSource::Estimate => LightModel::Directional,
            LightSource::EstimateAmbient => LightModel::AmbientDirectional,
            LightSource::Direction(d) => LightModel::KnownDirection(d),
        };
        estimate(&samples, model, self.seed)
    }

    /// Azimuth, prior and Laplacian rows: everything but the light.
    fn add_base_rows(&self, eq: &mut NormalEquations, pixels: &Pixels, prior: &ConvexityPrior) {
        let domain = eq.domain();
        let ops = Operators::new(domain);
        for k in 0..domain.len() {
            if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
                let (x, y) = domain.pixel(k);
                let w = f64::from(*prior.weight.get(x, y));
                let (sa, ca) = f64::from(*prior.azimuth.get(x, y)).sin_cos();
                if pixels.unlit[k] {
                    // No zenith or AoP here: only the prior's direction.
                    if w > 0.0 {
                        eq.add(&dx.combine(sa, &dy, -ca), 0.0, w);
                    }
                } else {
                    let (sp, cp) = pixels.aop[k].sin_cos();
                    eq.add(&dx.combine(sp, &dy, -cp), 0.0, 1.0);
                    if w > 0.0 {
                        let (st, ct) = pixels.theta[k].sin_cos();
                        eq.add(&dx.scaled(ct), -st * ca, w);
                        eq.add(&dy.scaled(ct), -st * sa, w);
                    }
                }
            }
            if self.lambda > 0.0
                && let Some(l) = ops.laplacian(k)
            {
                eq.add(&l, 0.0, self.lambda);
            }
        }
    }
}

/// Adds the shading-ratio rows for `lighting` (right-hand side 0) and, when
/// `candidates` is 2, for its flipped partner (right-hand side 1, same rows
/// with the sign of the right-hand side changed); returns how many.
fn add_shading_rows(
    eq: &mut NormalEquations,
    pixels: &Pixels,
    lighting: &Lighting,
    candidates: usize,
) -> usize {
    let domain = eq.domain();
    let ops = Operators::new(domain);
    let [lx, ly, lz] = lighting.vector;
    let mut count = 0;
    for k in 0..domain.len() {
        if pixels.dark[k] {
            continue;
        }
        if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
            let ct = pixels.theta[k].cos();
            let row = dx.combine(ct * lx, &dy, ct * ly);
            let value = ct * lz - (pixels.intensity[k] - lighting.ambient);
            eq.add_each(&row, &[value, -value][..candidates], 1.0);
            count += 1;
        }
    }
    count
}

/// Mean of `n_xy · outward` over mask pixels in a band along the boundary:
/// positive when the surface bends away from the camera towards the contour,
/// as a convex object's does. The band reaches [`BAND_FRACTION`] of the
/// largest boundary distance inwards (at least [`BAND_MIN`] pixels): right at
/// the contour the prior rows dominate and both light candidates look convex
/// (on the analytic sphere the two scores differ by < 1 % within 3 px, by
/// 40 % within a quarter of the radius).
fn boundary_agreement(domain: &Domain, normals: &[[f32; 3]], prior: &ConvexityPrior) -> f64 {
    let d_max = (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            *prior.distance.get(x, y)
        })
        .fold(0.0f32, f32::max);
    let band = (BAND_FRACTION * d_max).max(BAND_MIN);
    let (mut sum, mut count) = (0.0, 0usize);
    for (k, n) in normals.iter().enumerate() {
        let (x, y) = domain.pixel(k);
        if *prior.distance.get(x, y) > band || *prior.weight.get(x, y) == 0.0 {
            continue;
        }
        let (sa, ca) = f64::from(*prior.azimuth.get(x, y)).sin_cos();
        sum += f64::from(n[0]) * ca + f64::from(n[1]) * sa;
        count += 1;
    }
    if count == 0 { 0.0 } else { sum / count as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;
    use sfp_core::analytic::{AnalyticScene, Shape};
    use sfp_core::metrics::evaluate;
    use sfp_core::stokes::Polarimetry;
    use sfp_core::{Image, Mask};

    fn scene(shape: Shape, size: usize, light: [f64; 3]) -> AnalyticScene {
        AnalyticScene {
            shape,
            size,
            eta: 1.5,
            albedo: 0.8,
            light,
        }
    }

    /// Reconstructs an analytic view; returns MAE (degrees) and the run record.
    fn run(scene: &AnalyticScene, method: &Smith) -> (f64, serde_json::Value) {
        let view = scene.render().unwrap();
        let input = Input::from_view(&view.input).unwrap();
        let rec = method.reconstruct(&input).unwrap();
        let gt = view.gt.unwrap();
        let mask = view.input.mask.unwrap();
        let m = evaluate(&rec.normals, &gt.normals, &mask).unwrap();
        assert_eq!(m.missing, 0);
        (m.mae_deg, rec.run)
    }

    fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
        let dot: f64 = (0..3).map(|i| a[i] * b[i]).sum();
        let n = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (dot / (n(a) * n(b))).clamp(-1.0, 1.0).acos().to_degrees()
    }

    const LIGHT: [f64; 3] = [0.35, 0.25, 0.9];

    #[test]
    fn sphere_with_known_light_direction() {
        let method = Smith {
            light: LightSource::Direction(LIGHT),
            ..Smith::default()
        };
        let (mae, _) = run(&scene(Shape::Sphere, 128, LIGHT), &method);
        assert!(mae < 1.0, "MAE {mae}°");
    }

    #[test]
    fn sphere_with_estimated_light() {
        let (mae, run) = run(&scene(Shape::Sphere, 128, LIGHT), &Smith::default());
        let chosen = run["light"]["chosen"].as_u64().unwrap() as usize;
        let dir: Vec<f64> =
            serde_json::from_value(run["light"]["candidates"][chosen]["direction"].clone())
                .unwrap();
        let err = angle_deg([dir[0], dir[1], dir[2]], LIGHT);
        assert!(mae < 2.0 && err < 2.0, "MAE {mae}°, light error {err}°");
    }

    #[test]
    fn flip_is_resolved_in_every_quadrant() {
        // The estimator returns either member of the pair; count how often the
        // partner had to be taken, so the test exercises both paths.
        let mut flips = 0;
        for (sx, sy) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            let light = [0.4 * sx, 0.3 * sy, 0.87];
            for seed in [0, 1] {
                let method = Smith {
                    seed,
                    ..Smith::default()
                };
                let (mae, run) = run(&scene(Shape::Sphere, 64, light), &method);
                let chosen = run["light"]["chosen"].as_u64().unwrap() as usize;
                let c = &run["light"]["candidates"];
                let dir: [f64; 3] = serde_json::from_value(c[chosen]["direction"].clone()).unwrap();
                let score = |i: usize| c[i]["boundary_agreement"].as_f64().unwrap();
                assert!(
                    angle_deg(dir, light) < 2.0 && score(chosen) > score(1 - chosen) + 0.1,
                    "light {light:?} seed {seed}: chose {dir:?}, scores {} {}",
                    score(0),
                    score(1)
                );
                assert!(mae < 3.0, "light {light:?}: MAE {mae}°");
                flips += chosen;
            }
        }
        assert!(flips > 0 && flips < 8, "{flips} of 8 runs took the partner");
    }

    #[test]
    fn noisy_sphere_stays_close() {
        // Uniform noise of 0.5 % of full scale (σ ≈ 0.14 %) on every polarizer
        // image, fixed seed: light and shape degrade gracefully (measured:
        // MAE 2.5°, light error 0.06°).
        let mut view = scene(Shape::Sphere, 96, LIGHT).render().unwrap();
        let mut rng = Pcg64::seed_from_u64(5);
        for image in view.input.pol.iter_mut() {
            for v in image.data_mut() {
                let noisy = f64::from(*v) + 65535.0 * 0.005 * (rng.random::<f64>() - 0.5);
                *v = noisy.clamp(0.0, 65535.0) as u16;
            }
        }
        let input = Input::from_view(&view.input).unwrap();
        let rec = Smith::default().reconstruct(&input).unwrap();
        let gt = view.gt.unwrap();
        let m = evaluate(&rec.normals, &gt.normals, &input.mask).unwrap();
        let chosen = rec.run["light"]["chosen"].as_u64().unwrap() as usize;
        let dir: [f64; 3] =
            serde_json::from_value(rec.run["light"]["candidates"][chosen]["direction"].clone())
                .unwrap();
        let err = angle_deg(dir, LIGHT);
        assert!(
            m.mae_deg < 5.0 && err < 3.0,
            "MAE {}°, light error {err}°",
            m.mae_deg
        );
    }

    #[test]
    fn albedo_map_explains_texture() {
        // Texture the sphere: scale all four polarizer images by a(x, y),
        // which changes I_un but not DoP or AoP.
        let mut view = scene(Shape::Sphere, 96, LIGHT).render().unwrap();
        let texture = Image::from_fn(96, 96, |x, y| 0.6 + 0.4 * ((x / 8 + y / 8) % 2) as f32);
        for image in view.input.pol.iter_mut() {
            for (v, a) in image.data_mut().iter_mut().zip(texture.data()) {
                *v = (f32::from(*v) * a).round() as u16;
            }
        }
        let input = Input::from_view(&view.input).unwrap();
        let gt = view.gt.unwrap();
        let mae = |method: &Smith| {
            let rec = method.reconstruct(&input).unwrap();
            evaluate(&rec.normals, &gt.normals, &input.mask)
                .unwrap()
                .mae_deg
        };
        let with_map = mae(&Smith {
            albedo: Some(texture.map(|a| 0.8 * a)),
            ..Smith::default()
        });
        let without = mae(&Smith::default());
        assert!(
            with_map < 1.0 && without > 2.0 * with_map,
            "with map {with_map}°, without {without}°"
        );
    }

    #[test]
    fn sphere_with_ambient_model() {
        let method = Smith {
            light: LightSource::EstimateAmbient,
            ..Smith::default()
        };
        let (mae, _) = run(&scene(Shape::Sphere, 96, LIGHT), &method);
        assert!(mae < 2.0, "MAE {mae}°");
    }

    #[test]
    fn blobs_are_finite() {
        let (mae, _) = run(&scene(Shape::Blobs, 96, LIGHT), &Smith::default());
        assert!(mae.is_finite() && mae < 90.0, "MAE {mae}°");
    }

    /// Polarimetry and mask of an analytic sphere (size 48).
    fn sphere48() -> (Polarimetry, Mask) {
        let view = scene(Shape::Sphere, 48, LIGHT).render().unwrap();
        (view.input.polarimetry(), view.input.mask.unwrap())
    }

    fn assert_well_formed(rec: &Reconstruction, mask: &Mask) {
        for i in 0..mask.len() {
            let n = rec.normals.data()[i];
            if mask.data()[i] {
                assert!(n.iter().all(|v| v.is_finite()) && n[2] > 0.0);
                assert!(rec.height.data()[i].is_finite());
            } else {
                assert_eq!(n, [0.0; 3]);
                assert!(rec.height.data()[i].is_nan());
            }
        }
    }

    #[test]
    fn components_and_holes() {
        // The sphere's mask cut into a ring with a hole, a separate piece and
        // a lone pixel.
        let (pol, disc) = sphere48();
        let mask = Mask::from_fn(48, 48, |x, y| {
            let r2 = (x as f64 - 24.0).powi(2) + (y as f64 - 24.0).powi(2);
            *disc.get(x, y) && ((r2 > 16.0 && x < 28) || x > 31 || (x == 30 && y == 24))
        });
        let input = Input::new(pol, Some(mask.clone())).unwrap();
        let rec = Smith::default().reconstruct(&input).unwrap();
        assert_eq!(rec.run["counts"]["components"], 3);
        assert_well_formed(&rec, &mask);
    }

    #[test]
    fn bad_inputs_fail_cleanly_or_fall_back() {
        let (pol, disc) = sphere48();
        let (w, h) = disc.size();
        // Empty mask: error.
        assert!(Input::new(pol.clone(), Some(Mask::new(w, h, false))).is_err());
        // All-zero images: error.
        let zeros = Polarimetry {
            intensity: Image::new(w, h, 0.0),
            dop: Image::new(w, h, 0.0),
            aop: Image::new(w, h, 0.0),
        };
        assert!(Input::new(zeros, None).is_err());
        // One-pixel mask: too few pixels to fit a light, a clear error.
        let one = Mask::from_fn(w, h, |x, y| x == 20 && y == 20);
        let input = Input::new(pol.clone(), Some(one)).unwrap();
        assert!(Smith::default().reconstruct(&input).is_err());
        // NaN and infinite pixels leave the mask and are counted.
        let mut bad = pol.clone();
        *bad.dop.get_mut(20, 21) = f32::NAN;
        *bad.intensity.get_mut(25, 25) = f32::INFINITY;
        let input = Input::new(bad, Some(disc.clone())).unwrap();
        assert_eq!(input.dropped_nonfinite, 2);
        assert!(!*input.mask.get(20, 21));
        let rec = Smith::default().reconstruct(&input).unwrap();
        assert_well_formed(&rec, &input.mask);
        // DoP above the model's maximum is clamped (θ = 90°) and counted.
        let mut high = pol;
        high.dop = high.dop.map(|&d| 3.0 * d);
        let input = Input::new(high, Some(disc.clone())).unwrap();
        let rec = Smith::default().reconstruct(&input).unwrap();
        assert!(rec.run["counts"]["dop_clamped"].as_u64().unwrap() > 100);
        assert_well_formed(&rec, &disc);
    }

    /// Speed and memory at 1024² (~667k pixels, estimated light; run with
    /// `--release -- --ignored --nocapture`, under `/usr/bin/time -v` for
    /// the peak memory).
    #[test]
    #[ignore]
    fn timing_1024() {
        let view = scene(Shape::Sphere, 1024, LIGHT).render().unwrap();
        let input = Input::from_view(&view.input).unwrap();
        let start = Instant::now();
        let rec = Smith::default().reconstruct(&input).unwrap();
        println!(
            "smith 1024² ({} px): full method {:.3} s, run {}",
            input.mask.count(),
            start.elapsed().as_secs_f64(),
            rec.run["timings"]
        );
    }
}
