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
//! The fit alternates two steps from a starting surface (`FitStart`):
//! 1. **Shares.** Under the current normals the share that explains a
//!    pixel's polarization along its azimuth is `f = (ρ_d − q)/(ρ_d + ρ_s)`
//!    (`share`), known to the precision `(ρ_d + ρ_s)² / σ²`; each pixel takes
//!    the precision-weighted mean over a window of [`SHARE_RADIUS`], clamped
//!    to `[0, 1]` (materials are piecewise smooth). With `reflected_light`,
//!    each window also gets the strength `g ≥ 0` of a compact light's
//!    reflection off rough microfacets, polarized across the plane of the
//!    light and the view (one AoP for the view, that of the mean residual
//!    the shares alone leave), jointly with its share: the data less the
//!    diffuse part are `r ≈ f A + g e_L`, `A = −(ρ_d + ρ_s)(cos 2φ, sin 2φ)`.
//!    Where the lobe is wide, the facets that reflect the light face it
//!    whatever the surface does, so that polarization says nothing of the
//!    normal; read as the normal's, it bends a sphere into facets.
//! 2. **Heights.** One Levenberg–Marquardt step of the residuals
//!    `(v − m(∇z)) / σ` (`mixture`), each pixel's `σ²` the Stokes noise of
//!    its `s0` (`noise`) plus [`MODEL_SIGMA`]², linearised at the current
//!    gradient: rows over `z` on the shared sparse solver, with a damping
//!    row on each gradient and a weak Laplacian ([`SMOOTHNESS`]) where data
//!    vanish (a surface facing the camera is unpolarized). With
//!    `Model::shading`, each pixel's diffuse intensity `(1 − f) I` is a row
//!    too, under the smooth light fitted to the current normals
//!    (`shading`). A step that raises the cost is retried with more
//!    damping.
//!
//! What the polarization cannot fix: at η 1.5, `ρ_d / (ρ_d + ρ_s)` stays
//! at 0.040–0.046 for zeniths 10°–40°, so a share of about 4% makes any of
//! them unpolarized. A face towards the camera therefore keeps the zenith
//! of its start unless the intensity moves it (`reports/glossy.md`, "Why
//! faces towards the camera keep the start").
//!
//! The model is even in the gradient, so the fit keeps each pixel's sense
//! from the start; which of the 90°-apart azimuths holds, it decides. It
//! stops when the cost falls by less than [`TOLERANCE`] of a residual
//! variance per unknown, or after
//! [`MAX_ITERATIONS`] (`converged: false`). It runs coarse to fine
//! (`pyramid`): halved grids down to [`COARSEST_UNKNOWNS`], each level
//! started from the coarser one's surface and damping.

use crate::input::Input;
use crate::noise::StokesNoise;
use crate::solver::domain::Domain;
use crate::solver::lsq::{NormalEquations, Solver};
use crate::solver::operators::{Operators, Stencil};
use crate::solver::ordered_sum::ordered_sum;
use crate::solver::ordering::Ordering;
use crate::specular::limb::Limb;
use crate::specular::mixture::{Mixture, dops};
use crate::specular::pyramid::{Measured, double_heights, halve_heights};
use crate::specular::reflected_light::{CorePolarization, REFLECTED_LIGHT_SEEN};
use crate::specular::shading::Shading;
use crate::switch::Switch;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sfp_core::integral::Integral;
use sfp_core::{Error, Image, Mask, NormalMap, Result};

/// Model error of a normalised Stokes component: roughness, interreflection
/// and the light's own polarization, none of which the model holds.
pub const MODEL_SIGMA: f64 = 0.02;
/// Half-width of the window a pixel's share is averaged over. A wider
/// window ties more of a material to one share, which holds the zeniths
/// of diffuse objects, but blurs the share where the reflected
/// surroundings change it fast, which glossy objects need (256², fit on
/// every view, radius 3 / 8 / 16 / 48, mean MAE: glossy preset 14.32 /
/// 14.77 / 15.77 / 16.94°, its `--seed 11` draw 21.78 / 20.46 / 19.82 /
/// 20.36°, the same scenes without gloss 11.13 / 9.61 / 8.76 / 7.74°;
/// with the default's choice of views, glossy preset 17.72 / 18.37 /
/// 19.39° at 3 / 8 / 16). No width serves both; `reports/glossy.md`.
pub const SHARE_RADIUS: usize = 3;
/// Weight of the Laplacian rows relative to a data row of [`MODEL_SIGMA`].
pub const SMOOTHNESS: f64 = 0.03;
/// Fall of the cost per unknown below which a level has converged: a
/// hundredth of one residual variance, far below what changes a normal.
/// The variance is the modelled one (cost 1 per unknown) or, where the
/// model explains the data less well than that, the residuals' own (the
/// cost per unknown): a relative test alone would keep refining
/// noise-free data towards 0, an absolute one alone keeps fitting the
/// model error of real data (fruit capture: falls of 0.003–0.02 per
/// unknown a step at costs near 2.3, over 8–21 steps a level).
pub const TOLERANCE: f64 = 1e-2;
pub const MAX_ITERATIONS: usize = 60;
/// Unknowns from which a step is solved by conjugate gradients from the
/// current heights (`Solver::solve_near`), as SMSfP's own solves are (at
/// 42k unknowns 0.14 s a step against 0.19 s factorised).
const NEAR_MIN: usize = 20_000;
/// Relative residual at which a step's conjugate gradients stop. A step
/// is a direction the cost test then accepts or rejects, so solving the
/// linearised system beyond what the linearisation is worth buys nothing
/// (inexact Gauss–Newton): 512² sphere, finest level 6–9 iterations a
/// step instead of 93–109 at the solver's default 1e-6, same MAE (0.61°).
const STEP_TOLERANCE: f64 = 1e-3;
/// Damping of the first step, relative to a data row of [`MODEL_SIGMA`].
/// A finer level starts at the damping the coarser one ended with: its
/// start is the coarser optimum, where full Gauss–Newton steps hold (512²
/// sphere: 2 steps on each finer level instead of 7).
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

/// The reflection model the fit reads the polarization with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model {
    pub eta: f64,
    /// Also model a compact light reflected by rough microfacets
    /// (`Reading`): polarization across the plane of the light and the view,
    /// one direction for the whole view, each window its own strength.
    pub reflected_light: bool,
    /// Also fit the diffuse intensity under a smooth light (`shading`),
    /// with this relative `σ_I`: the method's own surface's shading
    /// residual.
    pub shading: Option<f64>,
}

/// The surface the fit starts from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitStart {
    /// The occluding contour's convex surface (`dome`): its azimuths point
    /// outwards everywhere, the sense a convex object has, whichever
    /// reflection dominates a pixel. On the glossy preset (22 views, 256²)
    /// the fit from it ends at 18.22° mean MAE, from SMSfP's stitched
    /// surface (`specular = "auto"`) at 24.69°: a start that read turned
    /// AoPs as diffuse keeps their sense, which the model cannot change.
    /// The dome is taken over every object: choosing SMSfP's surface over
    /// objects whose outline's DoP is below their own (reliefs seen
    /// face-on) helped the development views but, on two held-out draws
    /// of the preset, misjudged objects and reliefs both ways (66 views:
    /// 18.97° with that choice, 18.01° without).
    Dome,
    /// The dome and the crease-free membrane over the same outline
    /// (`dome::membrane`), keeping the fit that ends at the lower cost.
    /// Both start every pixel in the convex sense, so the cost compares
    /// only the zeniths they leave where the polarization says little
    /// (faces towards the camera, `reports/glossy.md`), and there the data
    /// they explain tell them apart. Fit everywhere on the glossy preset's
    /// three draws: 14.32°, 16.29°, 21.79° against the dome's 14.81°,
    /// 17.06°, 22.17°.
    #[default]
    Convex,
    /// The method's own surface.
    Stitched,
    /// Both: the fitted surface kept is the one whose normals explain the
    /// intensity better under a smooth light (`light::shading_residual`).
    Both,
}

/// Whether the surface fit under the mixed model runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MixedFit {
    Off,
    On,
    /// When the data say the polarization is not diffuse: read as
    /// diffuse, it asks for a refractive index beyond the η search's range
    /// (2.5, above every common dielectric), or the occluding contour is
    /// polarized along the outline (`limb`). SMSfP's search ends there on
    /// 11–12 of 22 views of each of three draws of the glossy preset, and
    /// on no view of `builtin`, `a`, `b` or their `--svbrdf` variants
    /// (1.18–1.68); the limb adds 2 views of the second draw and none of
    /// those presets. Or the deepest tenth of the mask is polarized beyond
    /// what reflection by the surface gives there (`reflected_light`).
    #[default]
    Auto,
}

impl Switch for MixedFit {
    const OFF: Self = MixedFit::Off;
    const ON: Self = MixedFit::On;
}

impl MixedFit {
    /// Whether the fit runs, and why (`run.json`: `model`), given whether
    /// the η search ended at its range's upper end (`None`: no search), the
    /// limb's polarization (`None`: no occluding outline) and the deepest
    /// tenth's (`None`: no lit mask pixel).
    pub fn decide(
        self,
        eta_at_upper_end: Option<bool>,
        limb: Option<&Limb>,
        core: Option<&CorePolarization>,
    ) -> (bool, &'static str) {
        match (self, eta_at_upper_end) {
            (MixedFit::On, _) => (true, "mixed_fit = on"),
            (MixedFit::Off, _) => (false, "mixed_fit = off"),
            (MixedFit::Auto, Some(true)) => (
                true,
                "read as diffuse, the polarization asks for a refractive index beyond the η \
                 search's range: specular reflection",
            ),
            (MixedFit::Auto, _) if limb.is_some_and(Limb::is_specular) => (
                true,
                "the polarization lies along the occluding contour, where diffuse \
                 polarization lies across it: specular reflection",
            ),
            (MixedFit::Auto, _) if core.is_some_and(CorePolarization::is_reflected_light) => {
                (true, REFLECTED_LIGHT_SEEN)
            }
            (MixedFit::Auto, Some(false)) => (
                false,
                "the diffuse reading finds a refractive index inside the η search's range",
            ),
            (MixedFit::Auto, None) => (false, "the refractive index was given (refine = false)"),
        }
    }
}

/// One surface the fit's choice weighed: where it started (or the
/// method's own surface, unfitted) and its shading residual.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// `"dome"`, `"membrane"`, `"stitched"` or `"own"` (the method's
    /// surface, unfitted).
    pub surface: String,
    pub shading_residual: Option<f64>,
    /// The fit's cost per pixel at the surface; for the method's own, the
    /// cost before the fit from it (when that fit ran). It chooses between
    /// the convex starts (`FitStart::Convex`), which share every pixel's
    /// sense; not against the method's own surface, which always costs
    /// more than the fit from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cost: Option<f64>,
}

/// What the fit did (`run.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    pub eta: f64,
    /// Steps over all levels, and per level from the coarsest.
    pub iterations: usize,
    #[serde(default)]
    pub level_iterations: Vec<usize>,
    pub converged: bool,
    /// Cost (squared weighted residuals of the polarization and, with
    /// `Model::shading`, of the diffuse intensity, and smoothness rows) per mask
    /// pixel, at the start and at the end.
    pub cost_start: f64,
    pub cost_end: f64,
    /// Share of the fitted pixels whose residual exceeds three of its `σ`:
    /// what the model leaves unexplained.
    pub unexplained: f64,
    /// Mean specular share of `s0` over the fitted pixels.
    #[serde(default)]
    pub specular_share: f64,
    /// AoP (degrees, camera frame) of the reflected compact light, when
    /// the fit modelled it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflected_light_aop_deg: Option<f64>,
    /// The surfaces weighed and the one kept, when there was a choice.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub candidates: Vec<Candidate>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kept: Option<String>,
}

/// Share of the fitted pixels left unexplained above which the fit warns.
pub const WARN_UNEXPLAINED: f64 = 0.05;

impl FitRecord {
    /// What `run.json` and stderr should say about the fit, with what to do.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.kept.as_deref() == Some("own") {
            // The method's own surface was kept: the fit's state is moot.
            return out;
        }
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
    /// Intensity; NaN where unusable for shading.
    intensity: f64,
    dx: Option<Stencil>,
    dy: Option<Stencil>,
    laplacian: Option<Stencil>,
}

/// Levels are halved (`pyramid`) while the finer one has more unknowns
/// than this: a level's factorisation then takes a few hundredths of a
/// second, and the fit's slow, long moves happen there.
pub const COARSEST_UNKNOWNS: usize = 16_384;

/// Fits heights to `input`'s measured polarization (AoPs as measured, not
/// turned by a labelling) from the heights `start` (NaN where unknown),
/// at refractive index `eta`, with the Stokes noise `noise`: coarse to
/// fine, each level from the coarser one's surface.
pub fn fit(
    input: &Input,
    start: &Image<f32>,
    model: Model,
    noise: &StokesNoise,
) -> Result<SurfaceFit> {
    if !start.same_size(&input.mask) {
        return Err(Error::invalid("starting heights and mask differ in size"));
    }
    let mut levels = vec![measured(input, start, noise)];
    while let Some(finer) = levels.last().filter(|l| l.mask.count() > COARSEST_UNKNOWNS) {
        levels.push(finer.halved());
    }
    let mut starts = vec![start.clone()];
    for level in &levels[1..] {
        let finer = starts.last().expect("the finest start");
        starts.push(halve_heights(finer, &level.mask));
    }
    let mut level_iterations = Vec::new();
    let mut surface: Option<Image<f32>> = None;
    let mut last = None;
    let mut damping = FIRST_DAMPING;
    for (level, level_start) in levels.iter().zip(&starts).rev() {
        let from = match &surface {
            Some(coarse) => double_heights(coarse, &level.mask),
            None => level_start.clone(),
        };
        let run = fit_level(level, &from, model, damping)?;
        damping = run.damping;
        level_iterations.push(run.iterations);
        surface = Some(run.domain.scatter(
            &run.z.iter().map(|&v| v as f32).collect::<Vec<_>>(),
            f32::NAN,
        ));
        last = Some(run);
    }
    let finest = last.expect("at least one level");
    let cost_start = {
        let domain = &finest.domain;
        let pixels = pixels(&levels[0], domain);
        let z: Vec<f64> = domain.gather(start).into_iter().map(f64::from).collect();
        let state = State::of(domain, &pixels, &z, model);
        cost(&pixels, &z, &state, model.eta)
    };
    let n = finest.domain.len().max(1) as f64;
    let record = FitRecord {
        eta: model.eta,
        iterations: level_iterations.iter().sum(),
        level_iterations,
        converged: finest.converged,
        cost_start: cost_start / n,
        cost_end: finest.cost / n,
        unexplained: finest.unexplained,
        specular_share: finest.state.share.iter().map(|r| r.share).sum::<f64>() / n,
        reflected_light_aop_deg: finest.state.light_aop.map(f64::to_degrees),
        candidates: Vec::new(),
        kept: None,
    };
    let domain = &finest.domain;
    let normals = crate::solver::integrate::normals_of(domain, &finest.z);
    let shares: Vec<f32> = finest.state.share.iter().map(|r| r.share as f32).collect();
    Ok(SurfaceFit {
        normals: domain.scatter(&normals, [0.0; 3]),
        height: surface.expect("at least one level"),
        share: domain.scatter(&shares, 0.0),
        record,
    })
}

/// The measured normalised Stokes vectors and weights over the pixels of
/// `input`'s mask where `start` is known.
fn measured(input: &Input, start: &Image<f32>, noise: &StokesNoise) -> Measured {
    let mask = Mask::from_fn(input.mask.width(), input.mask.height(), |x, y| {
        *input.mask.get(x, y) && start.get(x, y).is_finite()
    });
    let (w, h) = mask.size();
    let mut v = Image::new(w, h, [0.0; 2]);
    let mut weight = Image::new(w, h, 0.0);
    let shaded = input.shaded();
    let mut intensity = Image::new(w, h, f64::NAN);
    for y in 0..h {
        for x in 0..w {
            if !*mask.get(x, y) {
                continue;
            }
            let rho = f64::from(*input.dop.get(x, y));
            let psi = f64::from(*input.aop.get(x, y));
            let s0 = 2.0 * f64::from(*input.intensity.get(x, y));
            let usable = !*input.unlit.get(x, y) && !*input.saturated.get(x, y) && s0 > 0.0;
            let sigma2 = noise.dop_sigma(s0).powi(2) + MODEL_SIGMA * MODEL_SIGMA;
            *v.get_mut(x, y) = [rho * (2.0 * psi).cos(), rho * (2.0 * psi).sin()];
            *weight.get_mut(x, y) = if usable { sigma2.sqrt().recip() } else { 0.0 };
            if *shaded.get(x, y) {
                *intensity.get_mut(x, y) = f64::from(*input.intensity.get(x, y));
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

/// One level's fit.
struct LevelFit {
    domain: Domain,
    z: Vec<f64>,
    state: State,
    cost: f64,
    unexplained: f64,
    iterations: usize,
    converged: bool,
    damping: f64,
}

/// The alternation of the module doc on one level, from heights `start`
/// and damping `first_damping`.
fn fit_level(
    level: &Measured,
    start: &Image<f32>,
    model: Model,
    first_damping: f64,
) -> Result<LevelFit> {
    let eta = model.eta;
    let domain = Domain::new(&level.mask);
    let pixels = pixels(level, &domain);
    let mut z: Vec<f64> = domain.gather(start).into_iter().map(f64::from).collect();
    let mut solver = Solver::new(Ordering::default()).with_tolerance(STEP_TOLERANCE);
    let mut damping = first_damping;
    let mut state = State::of(&domain, &pixels, &z, model);
    let mut current = cost(&pixels, &z, &state, eta);
    let n = domain.len() as f64;
    let (mut iterations, mut converged) = (0, false);
    while iterations < MAX_ITERATIONS && !converged {
        iterations += 1;
        let before = current;
        loop {
            let next = step(&domain, &pixels, &z, &state, eta, damping, &mut solver)?;
            let c = cost(&pixels, &next, &state, eta);
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
        state = State::of(&domain, &pixels, &z, model);
        current = cost(&pixels, &z, &state, eta);
        converged = before - current <= TOLERANCE * current.max(n) || damping > MAX_DAMPING;
    }
    let unexplained = unexplained(&pixels, &z, &state.share, eta);
    Ok(LevelFit {
        domain,
        z,
        state,
        cost: current,
        unexplained,
        iterations,
        converged,
        damping,
    })
}

/// Each unknown's data and stencils.
fn pixels(level: &Measured, domain: &Domain) -> Vec<Pixel> {
    let ops = Operators::new(domain);
    (0..domain.len())
        .into_par_iter()
        .map(|k| {
            let (x, y) = domain.pixel(k);
            Pixel {
                v: *level.v.get(x, y),
                weight: *level.weight.get(x, y),
                intensity: *level.intensity.get(x, y),
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

/// Weighted squared residual of pixel `k`.
fn residual(pixels: &[Pixel], z: &[f64], share: &[Reading], eta: f64, k: usize) -> f64 {
    let px = &pixels[k];
    let Some((p, q)) = gradient(px, z) else {
        return 0.0;
    };
    let m = model(&share[k], eta, p, q).value;
    let (a, b) = (px.v[0] - m[0], px.v[1] - m[1]);
    px.weight * px.weight * (a * a + b * b)
}

/// The cost the steps lower: the squared weighted residuals of the
/// polarization and the shading, and the smoothness rows.
fn cost(pixels: &[Pixel], z: &[f64], state: &State, eta: f64) -> f64 {
    let smooth = SMOOTHNESS / MODEL_SIGMA;
    ordered_sum(pixels.len(), |k| {
        let px = &pixels[k];
        let roughness = px.laplacian.map_or(0.0, |l| (smooth * l.apply(z)).powi(2));
        let shading = match (&state.shading, gradient(px, z)) {
            (Some(s), Some((p, q))) => s
                .row(k, p, q, state.diffuse(px, k))
                .map_or(0.0, |(r, _)| r * r),
            _ => 0.0,
        };
        residual(pixels, z, &state.share, eta, k) + roughness + shading
    })
}

/// What one iteration holds fixed while it steps the heights: the
/// readings (step 1 of the module doc), the reflected light's AoP and the
/// smooth light of the diffuse intensity.
struct State {
    share: Vec<Reading>,
    /// The reflected light's AoP (radians), when modelled.
    light_aop: Option<f64>,
    shading: Option<Shading>,
}

impl State {
    /// The state under heights `z`.
    fn of(domain: &Domain, pixels: &[Pixel], z: &[f64], model: Model) -> State {
        let (share, light_aop) = shares(domain, pixels, z, model.eta, model.reflected_light);
        let shading = model.shading.and_then(|sigma| {
            let diffuse: Vec<_> = pixels
                .iter()
                .zip(&share)
                .map(|(px, r)| (gradient(px, z), (1.0 - r.share) * px.intensity))
                .collect();
            Shading::fit(&diffuse, sigma)
        });
        State {
            share,
            light_aop,
            shading,
        }
    }

    /// Pixel `k`'s diffuse intensity.
    fn diffuse(&self, px: &Pixel, k: usize) -> f64 {
        (1.0 - self.share[k].share) * px.intensity
    }
}

/// Share of the usable pixels with a residual beyond 3σ (two components:
/// `χ²₂ > 9` for a unit Gaussian has probability 1.1%).
fn unexplained(pixels: &[Pixel], z: &[f64], share: &[Reading], eta: f64) -> f64 {
    let usable = pixels.iter().filter(|p| p.weight > 0.0).count();
    let beyond = (0..pixels.len())
        .into_par_iter()
        .filter(|&k| residual(pixels, z, share, eta, k) > 9.0)
        .count();
    beyond as f64 / usable.max(1) as f64
}

/// What a pixel reflects besides the diffuse light: its specular share of
/// `s0`, and the polarization of a compact light reflected by rough
/// microfacets, which lies across the plane of the light and the view
/// whatever the pixel's own normal (one direction for the whole view).
#[derive(Clone, Copy, Debug, Default)]
struct Reading {
    share: f64,
    light: [f64; 2],
}

/// The model's normalised Stokes vector at gradient `(p, q)`.
fn model(reading: &Reading, eta: f64, p: f64, q: f64) -> crate::specular::mixture::Polarization {
    let mut m = Mixture {
        share: reading.share,
        eta,
    }
    .at(p, q);
    m.value[0] += reading.light[0];
    m.value[1] += reading.light[1];
    m
}

/// Step 1 of the module doc: every unknown's reading under heights `z`.
fn shares(
    domain: &Domain,
    pixels: &[Pixel],
    z: &[f64],
    eta: f64,
    reflected_light: bool,
) -> (Vec<Reading>, Option<f64>) {
    // Per pixel: the regressor of the share, `A = −(ρ_d + ρ_s)(cos 2φ,
    // sin 2φ)`, and the data less the diffuse part, `r = v − ρ_d (cos 2φ,
    // sin 2φ)`, so that `r ≈ f A + g e_L`.
    let regress = |px: &Pixel| -> ([f64; 2], [f64; 2]) {
        match gradient(px, z) {
            Some((p, q)) if p * p + q * q > 0.0 => {
                let (d, s) = dops(p, q, eta);
                let u = p * p + q * q;
                let e = [(p * p - q * q) / u, 2.0 * p * q / u];
                (
                    [-(d + s) * e[0], -(d + s) * e[1]],
                    [px.v[0] - d * e[0], px.v[1] - d * e[1]],
                )
            }
            _ => ([0.0; 2], px.v),
        }
    };
    let (w, h) = domain.size();
    let windowed = |value: &(dyn Fn(&Pixel) -> [f64; 5] + Sync)| {
        let mut evidence = vec![[0.0f64; 5]; w * h];
        let reading: Vec<(usize, [f64; 5])> = pixels
            .par_iter()
            .enumerate()
            .map(|(k, px)| {
                let (x, y) = domain.pixel(k);
                (y * w + x, value(px))
            })
            .collect();
        for (i, e) in reading {
            evidence[i] = e;
        }
        Integral::new(w, h, |i| evidence[i])
    };
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    // The share alone (no reflected light): the precision-weighted window
    // mean of each pixel's least-squares share.
    let alone = windowed(&|px: &Pixel| {
        let (a, r) = regress(px);
        let wt = px.weight * px.weight;
        [wt * dot(a, a), wt * dot(a, r), 0.0, 0.0, 0.0]
    });
    let share_alone = |x: usize, y: usize| {
        let [aa, ar, ..] = alone.window(x, y, SHARE_RADIUS);
        if aa > 0.0 {
            (ar / aa).clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    if !reflected_light {
        let readings = (0..domain.len())
            .into_par_iter()
            .map(|k| {
                let (x, y) = domain.pixel(k);
                Reading {
                    share: share_alone(x, y),
                    light: [0.0; 2],
                }
            })
            .collect();
        return (readings, None);
    }
    // The reflected light's direction: that of the mean residual the
    // shares alone leave.
    let mean_residual = |c: usize| {
        ordered_sum(domain.len(), |k| {
            let (x, y) = domain.pixel(k);
            let px = &pixels[k];
            let (a, r) = regress(px);
            let f = share_alone(x, y);
            px.weight * px.weight * (r[c] - f * a[c])
        })
    };
    let mean = [mean_residual(0), mean_residual(1)];
    let norm = (mean[0] * mean[0] + mean[1] * mean[1]).sqrt();
    if norm == 0.0 {
        return (vec![Reading::default(); domain.len()], None);
    }
    let e_l = [mean[0] / norm, mean[1] / norm];
    let joint = windowed(&|px: &Pixel| {
        let (a, r) = regress(px);
        let wt = px.weight * px.weight;
        [
            wt * dot(a, a),
            wt * dot(a, e_l),
            wt,
            wt * dot(a, r),
            wt * dot(e_l, r),
        ]
    });
    let readings = (0..domain.len())
        .into_par_iter()
        .map(|k| {
            let (x, y) = domain.pixel(k);
            let [aa, al, ll, ar, lr] = joint.window(x, y, SHARE_RADIUS);
            let det = aa * ll - al * al;
            let (mut f, mut g) = if det > 1e-9 * aa.max(1e-300) * ll.max(1e-300) {
                ((ar * ll - al * lr) / det, (aa * lr - al * ar) / det)
            } else {
                (if aa > 0.0 { ar / aa } else { 0.0 }, 0.0)
            };
            if g < 0.0 {
                g = 0.0;
                f = if aa > 0.0 { ar / aa } else { 0.0 };
            }
            if !(0.0..=1.0).contains(&f) {
                f = f.clamp(0.0, 1.0);
                g = if ll > 0.0 {
                    ((lr - al * f) / ll).max(0.0)
                } else {
                    0.0
                };
            }
            Reading {
                share: f,
                light: [g * e_l[0], g * e_l[1]],
            }
        })
        .collect();
    (readings, Some(0.5 * e_l[1].atan2(e_l[0])))
}

/// Step 2 of the module doc: the heights after one damped Gauss–Newton
/// step from `z` with shares `share` and damping `damping`.
fn step(
    domain: &Domain,
    pixels: &[Pixel],
    z: &[f64],
    state: &State,
    eta: f64,
    damping: f64,
    solver: &mut Solver,
) -> Result<Vec<f64>> {
    let scale = MODEL_SIGMA.recip();
    let mut eq = NormalEquations::new(domain);
    for (k, (px, f)) in pixels.iter().zip(&state.share).enumerate() {
        if let Some(lap) = px.laplacian {
            eq.add(&lap, 0.0, SMOOTHNESS / MODEL_SIGMA);
        }
        let (Some(dx), Some(dy)) = (px.dx, px.dy) else {
            continue;
        };
        let (p, q) = (dx.apply(z), dy.apply(z));
        let model = model(f, eta, p, q);
        if px.weight > 0.0 {
            for (i, j) in model.jacobian.iter().enumerate() {
                let row = dx.combine(j[0], &dy, j[1]);
                let value = px.v[i] - model.value[i] + j[0] * p + j[1] * q;
                eq.add(&row, value, px.weight);
            }
        }
        if let Some((r, [jp, jq])) = state
            .shading
            .as_ref()
            .and_then(|s| s.row(k, p, q, state.diffuse(px, k)))
        {
            // Rows are scaled by their weight: `r` and the slopes already are.
            let row = dx.combine(-jp, &dy, -jq);
            eq.add(&row, r - jp * p - jq * q, 1.0);
        }
        let d = damping.sqrt() * scale;
        eq.add(&dx, p, d);
        eq.add(&dy, q, d);
    }
    let solution = if domain.len() >= NEAR_MIN {
        solver.solve_near(&eq, Some(&[z.to_vec()]))?
    } else {
        solver.solve(&eq)?
    };
    Ok(solution.z.into_iter().next().unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dome::dome;
    use crate::noise::stokes_noise;
    use crate::solver::integrate::{height_from_normals, normals_from_height};
    use crate::test_support::{analytic, glossy_sphere, mixture, with_reflected_light};
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
        fitted_with(label, input, gt, start, polarization_only())
    }

    /// The model of the polarization alone at η 1.5.
    fn polarization_only() -> Model {
        Model {
            eta: 1.5,
            reflected_light: false,
            shading: None,
        }
    }

    /// As [`fitted`], with the reflection model `model`.
    fn fitted_with(
        label: &str,
        input: &Input,
        gt: &NormalMap,
        start: &Image<f32>,
        model: Model,
    ) -> (f64, f64, SurfaceFit) {
        let fit = fit(input, start, model, &stokes_noise(input)).unwrap();
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

    #[test]
    fn a_reflected_light_is_told_from_the_surface() {
        // A diffuse sphere whose upper half also reflects a compact light:
        // 0.1 of polarization at AoP 15°, whatever the normal there (rough
        // microfacets facing the light).
        let (input, gt) = analytic(Shape::Sphere, 64, 1.5);
        let input = with_reflected_light(input, 0.1, 15f64.to_radians(), |_, y| y < 32);
        let start = dome(&input.mask);
        let mut model = polarization_only();
        let (_, without, _) = fitted_with("light ignored", &input, &gt, &start, model);
        model.reflected_light = true;
        let (_, with, fit) = fitted_with("light modelled", &input, &gt, &start, model);
        assert!(with < 5.0 && with < without / 3.0, "{without}° → {with}°");
        let found = fit.record.reflected_light_aop_deg.unwrap();
        assert!(
            (found - 15.0).abs() < 3.0,
            "the light's AoP read as {found}°"
        );
    }

    #[test]
    fn the_shading_holds_the_zenith_a_free_share_leaves_loose() {
        // A sphere reflecting bright surroundings: where the share varies
        // (Fresnel reflectance, shading), a windowed share can explain a
        // wrong zenith; the diffuse intensity under a smooth light cannot.
        let (_, gt) = analytic(Shape::Sphere, 64, 1.5);
        for surroundings in [0.3, 1.0] {
            let (input, _) = glossy_sphere(64, surroundings);
            let start = dome(&input.mask);
            let mut model = polarization_only();
            let (_, without, _) = fitted_with("polarization", &input, &gt, &start, model);
            model.shading = Some(0.05);
            let (_, with, _) = fitted_with("with shading", &input, &gt, &start, model);
            assert!(
                with < 0.8 * without && with < 10.0,
                "surroundings {surroundings}: {without}° → {with}° with the shading"
            );
        }
    }
}
