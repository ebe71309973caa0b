//! Light estimation from the polarization image alone (Smith et al. 2016,
//! §5; TPAMI 2019 §4), for a Lambertian surface with albedo folded into the
//! light: `I_un = a + n · L` (`a` = ambient term, 0 for a point source).
//!
//! Each pixel's zenith `θ` (from the DoP) and AoP `ψ` give two candidate
//! normals `n± = (±sinθ cosψ, ±sinθ sinψ, cosθ)` (the azimuth ambiguity,
//! conventions.md §3), hence two candidate shading rows. The estimator
//! alternates between assigning every pixel the candidate that better explains
//! `I_un` for the current light and a linear least-squares solve for the light
//! over the assigned rows, until the assignment stops changing.
//!
//! The fit cannot tell `L` from `(−L_x, −L_y, L_z)` with all assignments
//! swapped (the convex/concave ambiguity): the caller reconstructs with both
//! and decides ([`LightEstimate::flipped`]).
//!
//! Choices made here: several starting lights, drawn from a seeded PCG stream
//! (upper hemisphere, length = robust maximum intensity), run on a strided
//! subsample of at most [`SUBSAMPLE`] pixels; the best start is then refined on
//! all pixels. Dark pixels (attached shadow, where `I_un = max(0, ·)` is not
//! linear) are excluded.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use sfp_core::{Error, Result};

/// Where a method's light comes from: the one light type of every method
/// (`smith`, `mahmoud`, `smsfp`) and of their configurations.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightSource {
    /// Estimate an unknown point-source (distant) light: `I = n · L`.
    Estimate,
    /// Estimate first-order spherical harmonics, ambient plus directional:
    /// `I = a + n · L`.
    EstimateAmbient,
    /// Known direction (towards the light, camera frame), unknown intensity:
    /// `I = s · n · d̂`.
    Direction([f64; 3]),
    /// Known light vector (direction × irradiance, camera frame) and albedo:
    /// `I_un = albedo · n·light` in the input's intensity units (the
    /// `meta.json` `light` and `albedo` of a rendered view).
    Known { light: [f64; 3], albedo: f64 },
}

impl LightSource {
    /// Whether the light is only known up to the convex/concave flip
    /// ([`Lighting::flipped`]), so a method must solve with both.
    pub fn is_ambiguous(self) -> bool {
        matches!(self, LightSource::Estimate | LightSource::EstimateAmbient)
    }

    /// Checks a known light: finite, with albedo > 0 (an estimated one has
    /// nothing to check).
    pub fn validate(self) -> Result<()> {
        match self {
            LightSource::Known { light, albedo }
                if !(light.iter().all(|v| v.is_finite()) && albedo > 0.0 && albedo.is_finite()) =>
            {
                Err(Error::invalid(format!(
                    "known light {light:?} with albedo {albedo} is not finite with albedo > 0"
                )))
            }
            _ => Ok(()),
        }
    }

    /// The light in intensity units divided by `intensity_scale` (the units
    /// of [`Sample::intensity`]), estimated from `samples` unless known.
    pub fn resolve(
        self,
        samples: &[Sample],
        seed: u64,
        intensity_scale: f64,
    ) -> Result<LightEstimate> {
        match self {
            LightSource::Known { light, albedo } => {
                self.validate()?;
                let lighting = Lighting {
                    ambient: 0.0,
                    vector: light.map(|v| v * albedo / intensity_scale),
                };
                Ok(LightEstimate {
                    rms_residual: rms_residual(samples, &lighting),
                    lighting,
                    iterations: 0,
                    starts: 0,
                })
            }
            _ => estimate(samples, self, seed),
        }
    }

    /// The `run.json` record of the source.
    pub fn record(self) -> serde_json::Value {
        serde_json::to_value(self).expect("light source serialises")
    }
}

/// The linear model the estimator fits (from a [`LightSource`]).
#[derive(Clone, Copy, Debug)]
enum Fit {
    /// `I = s · n · d̂`.
    Direction([f64; 3]),
    /// `I = n · L`.
    Point,
    /// `I = a + n · L`.
    Ambient,
    /// `I = a + s · n · d̂`.
    AmbientAlong([f64; 3]),
}

/// Fitted lighting, in the intensity units of the samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Ambient (order-0 SH) term `a`.
    pub ambient: f64,
    /// Directional term `L` (direction × intensity × albedo).
    pub vector: [f64; 3],
}

impl Lighting {
    /// The convex/concave partner `(−L_x, −L_y, L_z)`.
    pub fn flipped(&self) -> Lighting {
        let [x, y, z] = self.vector;
        Lighting {
            ambient: self.ambient,
            vector: [-x, -y, z],
        }
    }

    /// Unit direction of `L` (or +z for a zero vector).
    pub fn direction(&self) -> [f64; 3] {
        let [x, y, z] = self.vector;
        let n = (x * x + y * y + z * z).sqrt();
        if n > 0.0 {
            [x / n, y / n, z / n]
        } else {
            [0.0, 0.0, 1.0]
        }
    }
}

/// One pixel's observation: intensity, zenith and AoP.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub intensity: f64,
    pub zenith: f64,
    pub aop: f64,
}

/// Result of the estimation.
#[derive(Clone, Debug)]
pub struct LightEstimate {
    pub lighting: Lighting,
    /// Root-mean-square shading residual over the samples.
    pub rms_residual: f64,
    /// Alternation rounds of the final refinement.
    pub iterations: usize,
    /// Starting lights tried.
    pub starts: usize,
}

/// Starting lights tried on the subsample.
pub const STARTS: usize = 12;
/// Samples used for the multi-start phase.
pub const SUBSAMPLE: usize = 20_000;
/// Cap on alternation rounds (it converges in a handful).
const MAX_ROUNDS: usize = 100;

/// Fits `model` to `samples` with seeded starts (see the module doc); a
/// [`LightSource::Known`] light has nothing to fit (see
/// [`LightSource::resolve`]).
pub fn estimate(samples: &[Sample], model: LightSource, seed: u64) -> Result<LightEstimate> {
    let (model, params) = match model {
        LightSource::Direction(d) => (Fit::Direction(d), 1),
        LightSource::Estimate => (Fit::Point, 3),
        LightSource::EstimateAmbient => (Fit::Ambient, 4),
        LightSource::Known { .. } => {
            return Err(Error::invalid("a known light needs no estimation"));
        }
    };
    enough(samples, params)?;
    if let Fit::Direction(d) = model
        && !(d.iter().all(|v| v.is_finite()) && d.iter().any(|&v| v != 0.0))
    {
        return Err(Error::invalid(format!(
            "light direction {d:?} is not a finite non-zero vector"
        )));
    }
    let cand: Vec<[[f64; 3]; 2]> = samples.iter().map(candidates).collect();
    let scale = samples.iter().map(|s| s.intensity).fold(0.0, f64::max);
    let stride = samples.len().div_ceil(SUBSAMPLE);
    let sub: Vec<usize> = (0..samples.len()).step_by(stride).collect();

    let mut rng = Pcg64::seed_from_u64(seed);
    let mut best: Option<(Lighting, f64)> = None;
    let starts = if let Fit::Direction(_) = model {
        1
    } else {
        STARTS
    };
    for _ in 0..starts {
        let start = match model {
            Fit::Direction(d) => Lighting {
                ambient: 0.0,
                vector: scaled(d, scale),
            },
            _ => {
                // Uniform on the upper hemisphere.
                let z: f64 = rng.random_range(0.0..1.0);
                let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let r = (1.0 - z * z).sqrt();
                Lighting {
                    ambient: 0.0,
                    vector: [scale * r * phi.cos(), scale * r * phi.sin(), scale * z],
                }
            }
        };
        let (fit, residual, _) = alternate(samples, &cand, &sub, model, start)?;
        if best.is_none_or(|(_, r)| residual < r) {
            best = Some((fit, residual));
        }
    }
    let (start, _) = best.expect("at least one start");
    on_all(samples, &cand, model, start, starts)
}

/// Fails unless `samples` can determine `params` unknowns (twice as many).
fn enough(samples: &[Sample], params: usize) -> Result<()> {
    if samples.len() < 2 * params {
        return Err(Error::invalid(format!(
            "light estimation needs at least {} lit pixels, got {}",
            2 * params,
            samples.len()
        )));
    }
    Ok(())
}

/// `model` alternated over every sample from `start`: the estimate.
fn on_all(
    samples: &[Sample],
    cand: &[[[f64; 3]; 2]],
    model: Fit,
    start: Lighting,
    starts: usize,
) -> Result<LightEstimate> {
    let all: Vec<usize> = (0..samples.len()).collect();
    let (lighting, residual, iterations) = alternate(samples, cand, &all, model, start)?;
    Ok(LightEstimate {
        lighting,
        rms_residual: (residual / samples.len() as f64).sqrt(),
        iterations,
        starts,
    })
}

/// `I = a + s · n·d̂` fitted to `samples`: the fill light `a` and the
/// intensity `s` of a light whose direction `d` another fit found (SMSfP's
/// step 2 finds it with the diffuse model of conventions.md §3, whose
/// transmission factors these linear shading rows leave out).
pub fn fit_along(samples: &[Sample], d: [f64; 3]) -> Result<LightEstimate> {
    enough(samples, 2)?;
    let cand: Vec<[[f64; 3]; 2]> = samples.iter().map(candidates).collect();
    let scale = samples.iter().map(|s| s.intensity).fold(0.0, f64::max);
    let start = Lighting {
        ambient: 0.0,
        vector: scaled(d, scale),
    };
    let est = on_all(samples, &cand, Fit::AmbientAlong(d), start, 1)?;
    if est.lighting.ambient < 0.0 {
        // A fill light is not negative: without one, the intensity alone.
        return on_all(samples, &cand, Fit::Direction(d), start, 1);
    }
    Ok(est)
}

/// The two candidate normals of a sample.
fn candidates(s: &Sample) -> [[f64; 3]; 2] {
    let (st, ct) = s.zenith.sin_cos();
    let (sp, cp) = s.aop.sin_cos();
    [[st * cp, st * sp, ct], [-st * cp, -st * sp, ct]]
}

fn scaled(d: [f64; 3], s: f64) -> [f64; 3] {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|v| v * s / n)
}

fn predict(l: &Lighting, n: &[f64; 3]) -> f64 {
    l.ambient + n[0] * l.vector[0] + n[1] * l.vector[1] + n[2] * l.vector[2]
}

/// Root-mean-square residual of `lighting` over `samples`, each with the
/// candidate normal that explains it better.
fn rms_residual(samples: &[Sample], lighting: &Lighting) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    let sse: f64 = samples
        .iter()
        .map(|s| {
            candidates(s)
                .iter()
                .map(|n| (predict(lighting, n) - s.intensity).powi(2))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    (sse / samples.len() as f64).sqrt()
}

/// Alternates assignment and least squares over `subset` from `start`.
/// Returns the fit, its sum of squared residuals and the rounds taken.
fn alternate(
    samples: &[Sample],
    cand: &[[[f64; 3]; 2]],
    subset: &[usize],
    model: Fit,
    start: Lighting,
) -> Result<(Lighting, f64, usize)> {
    let mut light = start;
    let mut choice = vec![2u8; subset.len()];
    let mut round = 0;
    loop {
        round += 1;
        // Per-pixel and independent: parallel (the sums below stay serial,
        // so results do not depend on the thread count).
        let changed = choice
            .par_iter_mut()
            .zip(subset.par_iter())
            .map(|(c, &i)| {
                let e = |n: &[f64; 3]| (predict(&light, n) - samples[i].intensity).abs();
                let pick = u8::from(e(&cand[i][1]) < e(&cand[i][0]));
                let changed = *c != pick;
                *c = pick;
                changed
            })
            .reduce(|| false, |a, b| a || b);
        light = fit(samples, cand, subset, &choice, model)?;
        if !changed || round == MAX_ROUNDS {
            let sse = subset
                .iter()
                .zip(&choice)
                .map(|(&i, &c)| {
                    (predict(&light, &cand[i][c as usize]) - samples[i].intensity).powi(2)
                })
                .sum();
            return Ok((light, sse, round));
        }
    }
}

/// Linear least squares for the light given each sample's chosen normal.
fn fit(
    samples: &[Sample],
    cand: &[[[f64; 3]; 2]],
    subset: &[usize],
    choice: &[u8],
    model: Fit,
) -> Result<Lighting> {
    // Design row per model: [n·d̂] | [n] | [1, n].
    let row = |n: &[f64; 3]| -> ([f64; 4], usize) {
        match model {
            Fit::Direction(d) => {
                let d = scaled(d, 1.0);
                ([n[0] * d[0] + n[1] * d[1] + n[2] * d[2], 0.0, 0.0, 0.0], 1)
            }
            Fit::Point => ([n[0], n[1], n[2], 0.0], 3),
            Fit::Ambient => ([1.0, n[0], n[1], n[2]], 4),
            Fit::AmbientAlong(d) => {
                let d = scaled(d, 1.0);
                ([1.0, n[0] * d[0] + n[1] * d[1] + n[2] * d[2], 0.0, 0.0], 2)
            }
        }
    };
    let mut ata = [[0.0; 4]; 4];
    let mut atb = [0.0; 4];
    let mut p = 0;
    for (&i, &c) in subset.iter().zip(choice) {
        let (r, len) = row(&cand[i][c as usize]);
        p = len;
        // All four columns whatever the model uses (the others add zeros
        // and are not read): a fixed size the compiler unrolls and
        // vectorises, with the same sums in the same order as `len` columns.
        for a in 0..4 {
            atb[a] += r[a] * samples[i].intensity;
            for b in 0..4 {
                ata[a][b] += r[a] * r[b];
            }
        }
    }
    let x = solve_spd(&ata, &atb, p).ok_or_else(|| {
        Error::invalid("light estimation is degenerate (the lit normals do not span the light)")
    })?;
    Ok(match model {
        Fit::Direction(d) => Lighting {
            ambient: 0.0,
            vector: scaled(d, x[0]),
        },
        Fit::Point => Lighting {
            ambient: 0.0,
            vector: [x[0], x[1], x[2]],
        },
        Fit::Ambient => Lighting {
            ambient: x[0],
            vector: [x[1], x[2], x[3]],
        },
        Fit::AmbientAlong(d) => Lighting {
            ambient: x[0],
            vector: scaled(d, x[1]),
        },
    })
}

/// Share of the pixels whose shading rows are dropped, the worst first, by
/// [`shading_residual`]: highlights, cast shadows and interreflections,
/// which no light of this model explains.
pub const SHADING_TRIM: f64 = 0.1;

/// How well `normals` explain `intensity` over `usable` under the light of
/// this module's model (`I = a + n · L`, albedo folded in) fitted to them:
/// the root-mean-square residual over the best-explained
/// `1 −` [`SHADING_TRIM`] of the pixels (three rounds of fit and trim),
/// over their mean intensity. `None` with fewer than 4 usable pixels or a
/// degenerate fit. Of two surfaces for the same view, the one with the
/// lower residual is the one a smooth light can have lit.
pub fn shading_residual(normals: &[[f32; 3]], intensity: &[f32], usable: &[bool]) -> Option<f64> {
    let rows: Vec<([f64; 3], f64)> = normals
        .iter()
        .zip(intensity)
        .zip(usable)
        .filter(|&(_, &u)| u)
        .map(|((n, &i), _)| (n.map(f64::from), f64::from(i)))
        .collect();
    smooth_light(&rows).map(|fit| fit.relative_rms)
}

/// The light of this module's model fitted to `(normal, intensity)` rows
/// with the worst-explained [`SHADING_TRIM`] left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothLight {
    /// `(a, L_x, L_y, L_z)`: `I = a + n · L`.
    pub coefficients: [f64; 4],
    /// The largest absolute residual of the rows kept.
    pub bound: f64,
    /// Mean intensity of the rows kept.
    pub mean_intensity: f64,
    /// Root-mean-square residual of the rows kept over their mean intensity.
    pub relative_rms: f64,
}

impl SmoothLight {
    /// The intensity this light gives normal `n`.
    pub fn at(&self, n: [f64; 3]) -> f64 {
        let [a, x, y, z] = self.coefficients;
        a + x * n[0] + y * n[1] + z * n[2]
    }
}

/// [`SmoothLight`] fitted to `rows` by three rounds of fit and trim; `None`
/// with fewer than 4 rows, a degenerate fit or no intensity.
pub fn smooth_light(rows: &[([f64; 3], f64)]) -> Option<SmoothLight> {
    if rows.len() < 4 {
        return None;
    }
    let regressors = |n: &[f64; 3]| [1.0, n[0], n[1], n[2]];
    let mut keep = vec![true; rows.len()];
    let mut result = None;
    for _ in 0..3 {
        let (mut a, mut b) = ([[0.0; 4]; 4], [0.0; 4]);
        for ((n, i), _) in rows.iter().zip(&keep).filter(|&(_, &k)| k) {
            let r = regressors(n);
            for j in 0..4 {
                b[j] += r[j] * i;
                for k in 0..4 {
                    a[j][k] += r[j] * r[k];
                }
            }
        }
        let x = solve_spd(&a, &b, 4)?;
        let light = SmoothLight {
            coefficients: x,
            bound: f64::INFINITY,
            mean_intensity: 0.0,
            relative_rms: 0.0,
        };
        let residuals: Vec<f64> = rows.iter().map(|(n, i)| (light.at(*n) - i).abs()).collect();
        let mut sorted = residuals.clone();
        let k = ((sorted.len() - 1) as f64 * (1.0 - SHADING_TRIM)).round() as usize;
        let (_, bound, _) = sorted.select_nth_unstable_by(k, f64::total_cmp);
        let bound = *bound;
        keep = residuals.iter().map(|&r| r <= bound).collect();
        let (mut sq, mut sum, mut n) = (0.0, 0.0, 0usize);
        for ((r, (_, i)), _) in residuals.iter().zip(rows).zip(&keep).filter(|&(_, &k)| k) {
            sq += r * r;
            sum += i;
            n += 1;
        }
        result = (sum > 0.0).then(|| SmoothLight {
            bound,
            mean_intensity: sum / n as f64,
            relative_rms: (sq / n as f64).sqrt() / (sum / n as f64),
            ..light
        });
    }
    result
}

/// Solves the leading `p × p` block of a symmetric positive definite system
/// by Cholesky; `None` when it is not numerically positive definite.
fn solve_spd(a: &[[f64; 4]; 4], b: &[f64; 4], p: usize) -> Option<[f64; 4]> {
    let scale = (0..p).map(|i| a[i][i]).fold(0.0, f64::max);
    let mut l = [[0.0; 4]; 4];
    for i in 0..p {
        for j in 0..=i {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if s <= 1e-12 * scale {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0; 4];
    for i in 0..p {
        y[i] = (b[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0.0; 4];
    for i in (0..p).rev() {
        x[i] = (y[i] - (i + 1..p).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of a hemisphere lit by `l` (with ambient `a`), only lit pixels.
    fn hemisphere(l: [f64; 3], a: f64) -> Vec<Sample> {
        let mut out = Vec::new();
        let n = 60;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (
                    2.0 * (i as f64 + 0.5) / n as f64 - 1.0,
                    2.0 * (j as f64 + 0.5) / n as f64 - 1.0,
                );
                let r2 = x * x + y * y;
                if r2 >= 0.98 {
                    continue;
                }
                let nv = [x, y, (1.0 - r2).sqrt()];
                let shade = nv[0] * l[0] + nv[1] * l[1] + nv[2] * l[2];
                if shade <= 0.05 {
                    continue;
                }
                out.push(Sample {
                    intensity: a + shade,
                    zenith: nv[2].acos(),
                    aop: y.atan2(x).rem_euclid(std::f64::consts::PI),
                });
            }
        }
        out
    }

    fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
        let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        (dot / (na * nb)).clamp(-1.0, 1.0).acos().to_degrees()
    }

    #[test]
    fn directional_light_up_to_the_convex_concave_flip() {
        for l in [[0.5, 0.3, 0.8], [-0.6, 0.1, 0.7], [0.1, -0.7, 0.6]] {
            let est = estimate(&hemisphere(l, 0.0), LightSource::Estimate, 1).unwrap();
            let got = est.lighting;
            let err = angle_deg(got.vector, l).min(angle_deg(got.flipped().vector, l));
            assert!(err < 0.01, "light {l:?}: got {:?}", got.vector);
            assert!(est.rms_residual < 1e-9);
        }
    }

    #[test]
    fn known_direction_recovers_intensity() {
        let l = [0.4, -0.2, 0.9];
        let d = [0.4, -0.2, 0.9].map(|v: f64| v * 7.0);
        let est = estimate(&hemisphere(l, 0.0), LightSource::Direction(d), 1).unwrap();
        for (got, want) in est.lighting.vector.iter().zip(l) {
            assert!((got - want).abs() < 1e-9);
        }
    }

    #[test]
    fn ambient_and_directional() {
        let l = [0.3, 0.4, 0.7];
        let est = estimate(&hemisphere(l, 0.15), LightSource::EstimateAmbient, 3).unwrap();
        let got = est.lighting;
        let err = angle_deg(got.vector, l).min(angle_deg(got.flipped().vector, l));
        assert!(err < 0.01 && (got.ambient - 0.15).abs() < 1e-6, "{got:?}");
    }

    #[test]
    fn a_fill_and_an_intensity_along_a_given_direction() {
        let l = [0.3, 0.4, 0.7];
        let est = fit_along(&hemisphere(l, 0.15), [3.0, 4.0, 7.0]).unwrap();
        let got = est.lighting;
        for (g, w) in got.vector.iter().zip(l) {
            assert!((g - w).abs() < 1e-9, "{got:?}");
        }
        assert!((got.ambient - 0.15).abs() < 1e-9 && est.rms_residual < 1e-9);
    }

    #[test]
    fn too_few_samples_is_an_error() {
        let s = Sample {
            intensity: 1.0,
            zenith: 0.1,
            aop: 0.2,
        };
        assert!(estimate(&[s], LightSource::Estimate, 0).is_err());
        assert!(estimate(&[s; 10], LightSource::Direction([0.0; 3]), 0).is_err());
    }

    #[test]
    fn the_true_normals_explain_the_shading_better_than_partly_turned_ones() {
        // A hemisphere lit from the upper right with some ambient light,
        // and the same hemisphere with the azimuths of its right half turned
        // by 90° (turning all of them is a rotation, which a light turned
        // with it explains as well).
        let l = [0.4, 0.3, 0.8];
        let mut normals = Vec::new();
        let mut turned = Vec::new();
        let mut intensity = Vec::new();
        for y in -20..=20 {
            for x in -20..=20 {
                let (u, v) = (x as f64 / 21.0, y as f64 / 21.0);
                if u * u + v * v >= 1.0 {
                    continue;
                }
                let n = [u, v, (1.0 - u * u - v * v).sqrt()];
                let shading = 0.1 + (n[0] * l[0] + n[1] * l[1] + n[2] * l[2]).max(0.0);
                normals.push(n.map(|c| c as f32));
                let t = if x > 0 { [-n[1], n[0], n[2]] } else { n };
                turned.push(t.map(|c| c as f32));
                intensity.push(shading as f32);
            }
        }
        let usable: Vec<bool> = intensity.iter().map(|&i| i > 0.15).collect();
        let right = shading_residual(&normals, &intensity, &usable).unwrap();
        let wrong = shading_residual(&turned, &intensity, &usable).unwrap();
        assert!(right < 1e-3 && wrong > 0.05, "true {right}, turned {wrong}");
        assert!(shading_residual(&normals[..3], &intensity[..3], &usable[..3]).is_none());
    }
}
