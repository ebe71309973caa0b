//! Stage B, the full model (spec §4): the intensities themselves,
//! `I_j = max(0, a n·s) (1 + ρ cos 2(ϑ_j − φ))`, with the light (uniform
//! albedo) or each pixel's albedo (known light) estimated once from the
//! ratio stage's surface (`shading`), the shape-correlation prior tying
//! the surface to the ratio stage's (`correlation`) and the outward prior.
//!
//! Every pixel is read as diffuse here, as in the authors' code (their
//! full stage is passed an empty specular mask). A shadowed pixel
//! (`a n·s ≤ 0`) has model intensity 0 and, as the derivative of the clamp,
//! a zero gradient; the authors' code makes that gradient NaN and then 1
//! (Q6), which pushes shadowed pixels in an arbitrary direction.

use crate::solver::ordered_sum::ordered_sum;
use super::correlation::Blocks;
use super::level::Level;
use super::levenberg::{Cost, Exit, Outcome, ROUND, Row, minimise};
use super::model::{Pixel, Reflection};
use super::outward::{ROWS, outward_rows};
use crate::solver::lsq::Solver;
use rayon::prelude::*;
use sfp_core::Result;

/// The stage's weights (the authors' `scale`, `smooth`, `bd`).
#[derive(Clone, Copy, Debug)]
pub struct FullWeights {
    pub scale: f64,
    pub correlation: f64,
    pub boundary: f64,
}

/// Shading: `i_un = max(0, albedo_k · n·light)`.
#[derive(Clone, Debug)]
pub struct Shading {
    pub light: [f64; 3],
    /// One albedo per unknown, or `None` for 1 everywhere (the light then
    /// carries albedo and intensity scale).
    pub albedo: Option<Vec<f64>>,
}

/// The data rows at heights `z`, `P` per unknown.
pub fn intensity_rows(level: &Level, shading: &Shading, z: &[f64], rows: &mut [Row]) {
    let count = level.angle_count();
    let s = shading.light;
    rows.par_chunks_mut(count)
        .zip(level.intensities.par_chunks(count))
        .enumerate()
        .for_each(|(k, (out, observed))| {
            let (p, q) = level.gradients.at(k, z);
            let model = Pixel::of(p, q, level.eta, Reflection::Diffuse);
            let a = shading.albedo.as_ref().map_or(1.0, |al| al[k]);
            let g = 1.0 + p * p + q * q;
            let root = g.sqrt();
            let dot = s[2] - p * s[0] - q * s[1];
            let lit = a * dot / root;
            let (iun, diun) = if lit > 0.0 {
                let d = |si: f64, gi: f64| a * (-si / root - dot * gi / (g * root));
                (lit, [d(s[0], p), d(s[1], q)])
            } else {
                (0.0, [0.0; 2])
            };
            for (j, row) in out.iter_mut().enumerate() {
                let (f, df) = model.transmitted(level.angles[j]);
                let d = |i: usize| -(diun[i] * f + iun * df[i]);
                *row = Row {
                    value: observed[j] - iun * f,
                    gradient: level.gradients.combine(k, d(0), d(1)),
                };
            }
        });
}

/// Mean `|r|` of the data rows at `z` (the schedule's `μ`).
fn intensity_mean(level: &Level, shading: &Shading, z: &[f64]) -> f64 {
    let mut rows = vec![Row::default(); level.domain.len() * level.angle_count()];
    intensity_rows(level, shading, z, &mut rows);
    ordered_sum(rows.len(), |i| rows[i].value.abs()) / rows.len() as f64
}

struct FullCost<'a> {
    level: &'a Level,
    shading: &'a Shading,
    blocks: &'a Blocks,
    kernel: &'a [f64],
    correlation: f64,
    boundary: f64,
}

impl Cost for FullCost<'_> {
    fn len(&self) -> usize {
        let n = self.level.domain.len();
        n * self.level.angle_count() + self.blocks.len() + ROWS * self.level.targets.len()
    }

    fn evaluate(&self, z: &[f64], rows: &mut [Row]) {
        let n = self.level.domain.len();
        let (data, rest) = rows.split_at_mut(n * self.level.angle_count());
        let (corr, prior) = rest.split_at_mut(self.blocks.len());
        intensity_rows(self.level, self.shading, z, data);
        self.blocks.rows(z, self.kernel, self.correlation, corr);
        outward_rows(self.level, z, self.boundary, prior);
    }
}

/// Rounds at most (no longer last run, unlike the ratio stage).
const ROUNDS: usize = 5;

/// Runs the stage from the ratio stage's heights `z` (spec §4.4): up to 5
/// rounds of 10 iterations, the weights re-measured after each that hit
/// its cap.
pub fn solve_full(
    level: &Level,
    shading: &Shading,
    z: &mut [f64],
    weights: FullWeights,
    solver: &mut Solver,
) -> Result<Vec<Outcome>> {
    let kernel = z.to_vec();
    let blocks = Blocks::new(level);
    let mu0 = intensity_mean(level, shading, z);
    let cost_scale = mu0 / weights.scale;
    let cost = |mu: f64| FullCost {
        level,
        shading,
        blocks: &blocks,
        kernel: &kernel,
        correlation: weights.correlation * cost_scale * mu,
        boundary: weights.boundary * cost_scale * mu,
    };
    let mut current = cost(mu0);
    let mut outcomes = Vec::new();
    for _ in 0..ROUNDS {
        let out = minimise(&current, &level.domain, solver, z, &ROUND)?;
        outcomes.push(out);
        if out.exit != Exit::IterationCap {
            break;
        }
        current = cost(intensity_mean(level, shading, z));
    }
    Ok(outcomes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::yu2017::level::tests::sphere;
    use crate::methods::yu2017::levenberg::assert_gradients;
    use crate::methods::yu2017::shading::{estimate_albedo, estimate_light};

    #[test]
    fn gradients_match_finite_differences() {
        let light = [0.3, 0.2, 0.93];
        let (level, z) = sphere(light);
        let kernel: Vec<f64> = z.iter().enumerate().map(|(k, v)| v + 0.3 * (k as f64).cos()).collect();
        let z: Vec<f64> = z.iter().enumerate().map(|(k, v)| v + 0.2 * (k as f64).sin()).collect();
        let blocks = Blocks::new(&level);
        for shading in [estimate_light(&level, &z).unwrap(), estimate_albedo(&level, &z, light)] {
            let cost = FullCost {
                level: &level,
                shading: &shading,
                blocks: &blocks,
                kernel: &kernel,
                correlation: 50.0,
                boundary: 20.0,
            };
            assert_gradients(&cost, &z, 1e-4);
        }
    }

    #[test]
    fn light_and_albedo_are_recovered_from_the_true_surface() {
        let light = [0.3, 0.2, 0.93];
        let (level, z) = sphere(light);
        let estimated = estimate_light(&level, &z).unwrap().light;
        for (e, l) in estimated.iter().zip(light) {
            assert!((e - 0.8 * 30000.0 * l).abs() < 0.01 * 30000.0, "{estimated:?}");
        }
        // The stencils' normals are close inside (steep slopes cost a few
        // percent on this small sphere), one-sided on the rim.
        let albedo = estimate_albedo(&level, &z, light).albedo.unwrap();
        let mut off: Vec<f64> = (0..level.domain.len())
            .filter(|&k| level.laplacians[k].entries().count() == 5)
            .map(|k| (albedo[k] / (0.8 * 30000.0) - 1.0).abs())
            .collect();
        off.sort_by(f64::total_cmp);
        assert!(off[off.len() / 2] < 0.03 && off[off.len() - 1] < 0.2, "{off:?}");
    }
}
