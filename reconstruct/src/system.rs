//! The linear height-from-polarization system over any [`Domain`] (Smith et
//! al. 2016/2019; SMSfP paper §4.1–4.4, Eq. 18): one least-squares problem
//! `min ‖C z − d‖²` in the heights `z` of the domain, built from four row
//! families per pixel. `smith` solves it once over the whole mask; `smsfp`
//! solves it per region, with its own prior and zenith per region.
//!
//! Rows (derivatives by the smoothed central differences of `operators`):
//! 1. **azimuth** (conventions.md §3, the corrected form of Eqs. 8–9):
//!    `sin ψ · z_x − cos ψ · z_y = 0`, weight 1;
//! 2. **shading/polarization ratio** (Eq. 12 with `v = [0, 0, 1]`, albedo
//!    folded into the light, `I_un = a + n · L`):
//!    `cos θ (L_x z_x + L_y z_y) = cos θ L_z − (I_un − a)`, weight 1,
//!    intensities divided by the robust maximum so both rows are O(1);
//! 3. **convexity prior** (a [`ConvexityPrior`]: Smith's boundary prior, or
//!    SMSfP's MFCP azimuth, Eqs. 16–17), weight `w` per pixel:
//!    `cos θ z_x = −sin θ cos φ_prior`, `cos θ z_y = −sin θ sin φ_prior`;
//! 4. **Laplacian smoothness** `∇²z = 0` with weight `λ` at pixels whose
//!    4 neighbours are inside.
//!
//! Choices made here (the papers leave them open or get them wrong):
//! - dark pixels (`Input::dark`) carry no shading row but keep the others;
//! - unlit pixels (`Input::unlit`: attached or cast shadow) have no
//!   measurable DoP or AoP, so no azimuth row either, and the prior enters
//!   there as a direction-only row `sin φ_prior z_x − cos φ_prior z_y = 0`
//!   (weight `w`). Feeding their DoP of 0 (θ = 0) to the prior rows flattens
//!   the shadowed rim: 20° mean error on the outer tenth of the analytic
//!   sphere instead of 3°;
//! - pixels without a neighbour along x or along y carry no gradient rows
//!   (they still get a height through the Laplacian of their neighbours or,
//!   if isolated, height 0);
//! - an estimated light is known only up to the convex/concave pair `L`,
//!   `(−L_x, −L_y, L_z)`: both are solved and the one whose normals agree
//!   better with the outward prior directions in a band along the boundary
//!   is kept ([`boundary_agreement`]; never the "larger volume" rule). The
//!   band is a quarter of the largest boundary distance wide: closer to the
//!   contour the prior rows make both candidates look convex. Flipping the
//!   light only negates the shading rows, so `CᵀC` is shared: one
//!   factorisation, two solves.

use crate::input::Input;
use crate::light::{Lighting, Sample};
use crate::prior::ConvexityPrior;
use crate::solver::domain::Domain;
use crate::solver::integrate::normals_of;
use crate::solver::lsq::{NormalEquations, Solution, Solver};
use crate::solver::operators::Operators;
use sfp_core::{Error, Image, Result};
use std::time::Instant;

/// Per-pixel data the rows are built from, in unknown order.
#[derive(Clone, Debug)]
pub struct PixelData {
    /// Zenith `θ` from the DoP (radians).
    pub theta: Vec<f64>,
    /// AoP `ψ` (radians).
    pub aop: Vec<f64>,
    /// `I_un` divided by the robust maximum (and by the albedo, when known).
    pub intensity: Vec<f64>,
    /// No shading row (dark, or albedo ≤ 0).
    pub dark: Vec<bool>,
    /// No polarization signal at all.
    pub unlit: Vec<bool>,
    /// Weight of each pixel's azimuth row; `None`: 1 everywhere.
    pub azimuth_weight: Option<Vec<f64>>,
}

impl PixelData {
    /// The data of `input` at the unknowns of `domain` (which lives in the
    /// input's image), with zenith image `theta`. With an `albedo` map,
    /// intensities are divided by it and pixels with albedo ≤ 0 (or not
    /// finite) carry no shading row.
    pub fn gather(
        domain: &Domain,
        input: &Input,
        theta: &Image<f32>,
        albedo: Option<&Image<f32>>,
    ) -> Result<Self> {
        let mut data = PixelData {
            theta: domain.gather(theta).into_iter().map(f64::from).collect(),
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
            azimuth_weight: None,
        };
        if let Some(albedo) = albedo {
            if !albedo.same_size(&input.mask) {
                return Err(Error::invalid("albedo map and input differ in size"));
            }
            for (k, a) in domain.gather(albedo).into_iter().enumerate() {
                if a > 0.0 && a.is_finite() {
                    data.intensity[k] /= f64::from(a);
                } else {
                    data.dark[k] = true;
                }
            }
        }
        Ok(data)
    }

    /// Light-estimation samples: every pixel with a shading row, in unknown
    /// order (the one gathering path of every method's light estimate).
    pub fn light_samples(&self) -> Vec<Sample> {
        (0..self.theta.len())
            .filter(|&k| !self.dark[k])
            .map(|k| Sample {
                intensity: self.intensity[k],
                zenith: self.theta[k],
                aop: self.aop[k],
            })
            .collect()
    }
}

/// Prior rows whose sense is known only relative to the light (SMSfP's
/// AoP oriented by continuity): the zenith rows of the prior, per unknown,
/// with their right-hand side negated for the flipped light candidate, as
/// the convex/concave pair turns every sense the data do not fix.
#[derive(Clone, Debug)]
pub struct RelativePrior {
    /// Azimuth per unknown for the first light candidate (radians).
    pub azimuth: Vec<f64>,
    /// Row weight per unknown (0: no rows).
    pub weight: Vec<f64>,
}

impl RelativePrior {
    /// The same rows for the flipped light: every azimuth turned by π.
    pub fn turn(&mut self) {
        self.azimuth
            .iter_mut()
            .for_each(|a| *a += std::f64::consts::PI);
    }
}

/// The system of one domain: its data, prior and smoothness weight.
#[derive(Clone, Copy, Debug)]
pub struct System<'a> {
    pub domain: &'a Domain,
    pub data: &'a PixelData,
    /// Prior azimuth and weight, images of the domain's size.
    pub prior: &'a ConvexityPrior,
    /// Prior rows whose sense goes with the light candidate, if any.
    pub relative: Option<&'a RelativePrior>,
    /// Laplacian smoothness weight `λ`.
    pub lambda: f64,
}

/// The solution for one light candidate.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// Heights per unknown, zero mean per connected component.
    pub z: Vec<f64>,
    /// Unit normals per unknown (of `z`, through the same stencils).
    pub normals: Vec<[f32; 3]>,
    /// Boundary agreement ([`boundary_agreement`]).
    pub score: f64,
}

/// The solved system: every light candidate, and the one its own boundary
/// agreement prefers.
#[derive(Clone, Debug)]
pub struct Solved {
    /// The estimate first, then its convex/concave partner when ambiguous.
    pub candidates: Vec<Candidate>,
    /// Index of the candidate with the better boundary agreement (the
    /// estimate itself on a tie).
    pub chosen: usize,
    pub rows: usize,
    pub shading_rows: usize,
    pub components: usize,
    pub symbolic_reused: usize,
    pub seconds_assembly: f64,
    pub seconds_symbolic: f64,
    pub seconds_numeric: f64,
}

/// The boundary band that decides between light candidates reaches this
/// fraction of the largest boundary distance inwards, and at least
/// `BAND_MIN` pixels.
const BAND_FRACTION: f32 = 0.25;
const BAND_MIN: f32 = 3.0;

impl<'a> System<'a> {
    /// Azimuth, prior and Laplacian rows: everything but the light.
    pub fn add_base_rows(&self, eq: &mut NormalEquations) {
        let (domain, data, prior) = (self.domain, self.data, self.prior);
        let ops = Operators::new(domain);
        for k in 0..domain.len() {
            if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
                let (x, y) = domain.pixel(k);
                let w = f64::from(*prior.weight.get(x, y));
                let (sa, ca) = f64::from(*prior.azimuth.get(x, y)).sin_cos();
                if data.unlit[k] {
                    // No zenith or AoP here: only the prior's direction.
                    if w > 0.0 {
                        eq.add(&dx.combine(sa, &dy, -ca), 0.0, w);
                    }
                } else {
                    let (sp, cp) = data.aop[k].sin_cos();
                    let weight = data.azimuth_weight.as_ref().map_or(1.0, |w| w[k]);
                    eq.add(&dx.combine(sp, &dy, -cp), 0.0, weight);
                    if w > 0.0 {
                        let (st, ct) = data.theta[k].sin_cos();
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

    /// Adds the shading-ratio rows for `lighting` (right-hand side 0) and,
    /// when `candidates` is 2, for its flipped partner (right-hand side 1,
    /// same rows with the sign of the right-hand side changed); returns how
    /// many.
    pub fn add_shading_rows(
        &self,
        eq: &mut NormalEquations,
        lighting: &Lighting,
        candidates: usize,
    ) -> usize {
        let (domain, data) = (self.domain, self.data);
        let ops = Operators::new(domain);
        let [lx, ly, lz] = lighting.vector;
        let mut count = 0;
        for k in 0..domain.len() {
            if data.dark[k] {
                continue;
            }
            if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
                let ct = data.theta[k].cos();
                let row = dx.combine(ct * lx, &dy, ct * ly);
                let value = ct * lz - (data.intensity[k] - lighting.ambient);
                eq.add_each(&row, &[value, -value][..candidates], 1.0);
                count += 1;
            }
        }
        count
    }

    /// Adds the rows of the relative prior, if any: right-hand side 0 as
    /// given, 1 (the flipped light) negated.
    pub fn add_relative_rows(&self, eq: &mut NormalEquations, candidates: usize) {
        let Some(relative) = self.relative else {
            return;
        };
        let ops = Operators::new(self.domain);
        for k in 0..self.domain.len() {
            let w = relative.weight[k];
            if w <= 0.0 || self.data.unlit[k] {
                continue;
            }
            if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
                let (st, ct) = self.data.theta[k].sin_cos();
                let (sa, ca) = relative.azimuth[k].sin_cos();
                eq.add_each(&dx.scaled(ct), &[-st * ca, st * ca][..candidates], w);
                eq.add_each(&dy.scaled(ct), &[-st * sa, st * sa][..candidates], w);
            }
        }
    }

    /// Solves for `lighting` and, when `ambiguous`, its convex/concave
    /// partner too, keeping the candidate whose normals agree better with
    /// the prior along the boundary (the estimate itself on a tie).
    pub fn solve(
        &self,
        solver: &mut Solver,
        lighting: &Lighting,
        ambiguous: bool,
    ) -> Result<Solved> {
        let candidates = if ambiguous { 2 } else { 1 };
        let start = Instant::now();
        // One system, one right-hand side per light candidate: the flipped
        // light negates the shading rows' coefficients, which leaves CᵀC
        // unchanged and negates their right-hand side instead.
        let mut eq = NormalEquations::with_right_hand_sides(self.domain, candidates);
        self.add_base_rows(&mut eq);
        let shading_rows = self.add_shading_rows(&mut eq, lighting, candidates);
        self.add_relative_rows(&mut eq, candidates);
        let seconds_assembly = start.elapsed().as_secs_f64();
        let Solution {
            z,
            components,
            symbolic_reused,
            seconds_symbolic,
            seconds_numeric,
            ..
        } = solver.solve(&eq)?;
        let band = agreement_band(self.domain, self.prior);
        let candidates: Vec<Candidate> = z
            .into_iter()
            .map(|z| {
                let normals = normals_of(self.domain, &z);
                let score = boundary_agreement(self.domain, &normals, self.prior, band);
                Candidate { z, normals, score }
            })
            .collect();
        let chosen =
            usize::from(candidates.len() == 2 && candidates[1].score > candidates[0].score);
        Ok(Solved {
            candidates,
            chosen,
            rows: eq.rows(),
            shading_rows,
            components,
            symbolic_reused,
            seconds_assembly,
            seconds_symbolic,
            seconds_numeric,
        })
    }
}

/// The band [`boundary_agreement`] uses for a solved system: a quarter of
/// the largest boundary distance (at least 3 pixels). Right at the contour
/// the prior rows dominate and both light candidates look convex (on the
/// analytic sphere the two scores differ by < 1 % within 3 px, by 40 %
/// within a quarter of the radius).
pub fn agreement_band(domain: &Domain, prior: &ConvexityPrior) -> f32 {
    let d_max = (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            *prior.distance.get(x, y)
        })
        .fold(0.0f32, f32::max);
    (BAND_FRACTION * d_max).max(BAND_MIN)
}

/// Mean of `n_xy · outward` over the unknowns within `band` pixels of the
/// boundary where the prior has weight (normals `[0, 0, 0]` are skipped):
/// positive when the surface bends away from the camera towards the contour,
/// as a convex object's does.
pub fn boundary_agreement(
    domain: &Domain,
    normals: &[[f32; 3]],
    prior: &ConvexityPrior,
    band: f32,
) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for (k, n) in normals.iter().enumerate() {
        let (x, y) = domain.pixel(k);
        if *n == [0.0; 3] || *prior.distance.get(x, y) > band || *prior.weight.get(x, y) == 0.0 {
            continue;
        }
        let (sa, ca) = f64::from(*prior.azimuth.get(x, y)).sin_cos();
        sum += f64::from(n[0]) * ca + f64::from(n[1]) * sa;
        count += 1;
    }
    if count == 0 { 0.0 } else { sum / count as f64 }
}
