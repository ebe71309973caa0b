//! Conjugate gradients on the normal equations `CᵀC z = Cᵀd`,
//! preconditioned by one multigrid V-cycle (`multigrid`): the solver of
//! systems too large to factorise, in memory linear in the bounding box
//! (12 single-precision planes of it and the double-precision diagonal,
//! about as much again for the coarse levels' 4×4 blocks, and a few
//! double-precision vectors; 1.28 GB peak for Atkinson's integration of a
//! 2.5 M-pixel capture, against 5.47 GB factorised) instead of a
//! Cholesky factor's `O(n log n)` (≈ 3.5 KB per pixel at 2.5 M pixels).
//!
//! The membrane of `lsq` is left out (see `pieces`): `CᵀC` is then
//! singular, one constant per piece. The right-hand side has no part along
//! those constants (every row's coefficients sum to zero; the rounding left
//! is projected out), so conjugate gradients converge on the other modes;
//! the constants the V-cycle adds do not change a residual and are removed
//! at the end (zero mean per piece).
//!
//! Sums run over fixed chunks and are added in order, so the result does not
//! depend on the number of threads.

use super::multigrid::{Grid, Level, Multigrid};
use crate::solver::domain::{Domain, gather_at, scatter_at};
use crate::solver::ordered_sum::ordered_sum;
use rayon::prelude::*;

/// Stop when `‖b − A z‖ ≤ TOLERANCE ‖b‖` (`lsq::Solver`'s default; the
/// integration of normals into heights sets its own). Smith's normals of the fruit
/// capture at 1224×1024 against the factorisation's: 1e-3 0.028° MAE,
/// 1e-4 0.0057°, 1e-5 0.0029°, 1e-6 0.0037° (the factorisation's own
/// rounding on that system); SMSfP's at 1e-5 0.0102° (its refinement
/// compounds the differences), hence 1e-6.
pub(crate) const TOLERANCE: f64 = 1e-6;

/// Iterations before giving up (the caller falls back to the direct solver).
pub(crate) const MAX_ITERATIONS: usize = 300;

/// Elements per chunk of a dot product (fixed: see the module doc).
const CHUNK: usize = 1 << 14;

/// The normal equations of a domain on its bounding box.
pub(crate) struct BoxSystem<'a> {
    domain: &'a Domain,
    /// Storage index of every unknown.
    index: Vec<usize>,
    level: Level,
}

impl<'a> BoxSystem<'a> {
    /// `upper` (13-slot rows per unknown) on the bounding box of `domain`.
    pub fn new(domain: &'a Domain, upper: &[[f64; 13]]) -> Self {
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        for k in 0..domain.len() {
            let (x, y) = domain.pixel(k);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        let grid = Grid::new(x1 + 1 - x0, y1 + 1 - y0);
        let index: Vec<usize> = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                grid.at((x - x0) as isize, (y - y0) as isize)
            })
            .collect();
        let mut planes = vec![vec![0.0f64; grid.len()]; 13];
        for (k, row) in upper.iter().enumerate() {
            let i = index[k];
            for (s, &v) in row.iter().enumerate() {
                planes[s][i] = v;
            }
        }
        BoxSystem {
            domain,
            index,
            level: Level::new(grid, planes),
        }
    }

    /// Solves for `rhs` (one value per unknown) with pieces `label` (`count`
    /// of them), zero mean on each, starting from `guess` (zero when
    /// `None`); `None` when it does not converge. Also returns the
    /// iterations taken. The stopping rule (`‖r‖ ≤ tolerance ‖rhs‖`) is
    /// relative to `rhs` whatever the start, so a guess changes the
    /// iterations, not the accuracy.
    pub fn solve(
        &self,
        multigrid: &mut Multigrid,
        rhs: &[f64],
        guess: Option<&[f64]>,
        label: &[u32],
        count: usize,
        tolerance: f64,
    ) -> (Option<Vec<f64>>, usize) {
        let n = self.level.grid.len();
        let b = self.scatter(&project(rhs, label, count));
        let norm_b = dot(&b, &b).sqrt();
        if norm_b == 0.0 {
            return (Some(vec![0.0; self.domain.len()]), 0);
        }
        let converged = |r: &[f64]| dot(r, r).sqrt() <= tolerance * norm_b;
        let solution = |x: &[f64]| Some(project(&self.gather(x), label, count));
        let (mut x, mut r) = match guess {
            Some(guess) => {
                let x = self.scatter(guess);
                let mut r = b.clone();
                self.level.residual(Some(&b), &x, &mut r);
                (x, r)
            }
            None => (vec![0.0; n], b),
        };
        if converged(&r) {
            return (solution(&x), 0);
        }
        let mut z = vec![0.0; n];
        multigrid.apply(&self.level, &r, &mut z);
        let mut p = z.clone();
        let mut q = vec![0.0; n];
        let mut rz = dot(&r, &z);
        for iteration in 1..=MAX_ITERATIONS {
            self.level.residual(None, &p, &mut q);
            let alpha = rz / dot(&p, &q);
            axpy(alpha, &p, &mut x);
            axpy(-alpha, &q, &mut r);
            if !alpha.is_finite() {
                return (None, iteration);
            }
            if converged(&r) {
                return (solution(&x), iteration);
            }
            multigrid.apply(&self.level, &r, &mut z);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            p.par_chunks_mut(CHUNK)
                .zip(z.par_chunks(CHUNK))
                .for_each(|(p, z)| p.iter_mut().zip(z).for_each(|(p, &z)| *p = z + beta * *p));
        }
        (None, MAX_ITERATIONS)
    }

    /// The finest level (the multigrid hierarchy is built below it).
    pub fn level(&self) -> &Level {
        &self.level
    }

    /// The values of `grid` (on the box grid) at the unknowns.
    fn gather(&self, grid: &[f64]) -> Vec<f64> {
        gather_at(&self.index, grid)
    }

    /// Per-unknown values on the box grid (zero elsewhere).
    fn scatter(&self, values: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.level.grid.len()];
        scatter_at(&self.index, values, &mut out);
        out
    }
}

/// `values` minus their mean over each component.
fn project(values: &[f64], label: &[u32], count: usize) -> Vec<f64> {
    let mut sum = vec![(0.0, 0usize); count];
    for (&v, &l) in values.iter().zip(label) {
        sum[l as usize].0 += v;
        sum[l as usize].1 += 1;
    }
    values
        .iter()
        .zip(label)
        .map(|(&v, &l)| {
            let (s, c) = sum[l as usize];
            v - s / c as f64
        })
        .collect()
}

/// `aᵀb`, summed in a fixed order.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    ordered_sum(a.len().min(b.len()), |i| a[i] * b[i])
}

/// `y += a x`.
fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    y.par_chunks_mut(CHUNK)
        .zip(x.par_chunks(CHUNK))
        .for_each(|(y, x)| y.iter_mut().zip(x).for_each(|(y, &x)| *y += a * x));
}

#[cfg(test)]
mod tests {
    use crate::solver::domain::Domain;
    use crate::solver::lsq::{NormalEquations, Solution, Solver};
    use crate::solver::operators::Operators;
    use crate::solver::ordering::Ordering;
    use sfp_core::Mask;

    /// A 128² disc and the rows of `integrate` for a smooth gradient field.
    fn disc() -> Domain {
        Domain::new(&Mask::from_fn(128, 128, |x, y| {
            let (dx, dy) = (x as f64 - 63.5, y as f64 - 63.5);
            dx * dx + dy * dy < 62.0 * 62.0
        }))
    }

    fn integration(domain: &Domain) -> NormalEquations<'_> {
        let ops = Operators::new(domain);
        let mut eq = NormalEquations::new(domain);
        for k in 0..domain.len() {
            let (x, y) = domain.pixel(k);
            let (u, v) = (x as f64 / 20.0, y as f64 / 20.0);
            let (gx, gy) = (u.sin() * v.cos(), 0.3 * (u + v).cos());
            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
            eq.add(&ops.dx(k).unwrap(), gx, nz);
            eq.add(&ops.dy(k).unwrap(), gy, nz);
        }
        eq
    }

    fn iterate(eq: &NormalEquations) -> Solution {
        Solver::new(Ordering::default())
            .with_iterative_min(0)
            .solve(eq)
            .unwrap()
    }

    #[test]
    fn integration_converges_in_few_iterations() {
        // The central differences leave the modes near (−1)^x, (−1)^y and
        // (−1)^(x+y) nearly free, as well as the smooth ones; a hierarchy
        // that carries only the smooth ones took 36 iterations here, this
        // one 9 (see `multigrid`).
        let domain = disc();
        let iterations = iterate(&integration(&domain)).iterations;
        assert!((1..=25).contains(&iterations), "{iterations} iterations");
    }

    #[test]
    fn the_solution_does_not_depend_on_the_thread_count() {
        let domain = disc();
        let eq = integration(&domain);
        let solve = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| iterate(&eq))
        };
        let (one, three) = (solve(1), solve(3));
        assert!(one.iterations > 0);
        assert_eq!(one.z, three.z);
    }
}
