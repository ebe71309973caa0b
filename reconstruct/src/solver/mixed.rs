//! Mixed-precision solves of large systems: the Cholesky factor in single
//! precision, the answer in double.
//!
//! A single-precision factor takes half the memory, and its factorisation
//! streams and faults in half the bytes with twice the SIMD lanes (a half
//! disc of 333k unknowns, as in the 1024² sphere's split: 0.93 s instead of
//! 1.46 s). Its solve `K̃⁻¹` is accurate to about `κ(K) · 2⁻²⁴` only, too little for plain
//! iterative refinement on the integration systems (`κ` grows with the
//! image: 1024² still short of double accuracy after 10 steps), so it
//! preconditions conjugate gradients in double precision instead, which
//! reach it in 3–4 solves with the factor (256² to 1024² spheres). The
//! stopping test is LAPACK's (`dsposv`): `‖r‖∞ ≤ ‖z‖∞ ‖K‖∞ ε √n`, the
//! backward error of a double-precision solve. A system too ill-conditioned
//! for single precision (the factorisation fails or the iteration stalls) is
//! factorised again in double by the caller.

use super::slots::{Entries, SLOTS, slot_pixel, slot_source};
use crate::solver::domain::{Domain, gather_at, scatter_at};
use rayon::prelude::*;
use sfp_core::Result;

/// Systems with at least this many unknowns are solved in mixed precision.
pub(crate) const MIXED_MIN: usize = 20_000;

/// Iterations before giving up (each a solve with the factor).
const MAX_STEPS: usize = 20;

/// Solves `K z = b` on the unknowns `system` for every right-hand side of
/// `rhs` (`K` = `matrix` in the 13-slot layout; `rhs` and `z` indexed by
/// domain unknown, only `system`'s written) by conjugate gradients
/// preconditioned with the approximate solves of `approximate`; `false` when
/// they do not converge.
pub(crate) fn refine(
    domain: &Domain,
    matrix: Entries,
    system: &[usize],
    rhs: &[Vec<f64>],
    z: &mut [Vec<f64>],
    approximate: impl Fn(&[Vec<f64>], &mut [Vec<f64>]) -> Result<()>,
) -> Result<bool> {
    let bound = f64::EPSILON * (system.len() as f64).sqrt() * matrix_norm(domain, matrix, system);
    // Domain-indexed buffers `approximate` reads and writes.
    let mut input: Vec<Vec<f64>> = rhs.iter().map(|b| vec![0.0; b.len()]).collect();
    let mut output = input.clone();
    // Domain-indexed buffers the products spread their columns into (zero
    // off `system`, kept so every step does not allocate them again).
    let mut spread = input.clone();
    spread.truncate(PASS_COLUMNS);
    let mut precondition = |r: &[Vec<f64>]| -> Result<Vec<Vec<f64>>> {
        for (to, from) in input.iter_mut().zip(r) {
            scatter_at(system, from, to);
        }
        approximate(&input, &mut output)?;
        Ok(output.iter().map(|o| gather_at(system, o)).collect())
    };
    let mut r: Vec<Vec<f64>> = rhs.iter().map(|b| gather_at(system, b)).collect();
    let mut x: Vec<Vec<f64>> = r.iter().map(|r| vec![0.0; r.len()]).collect();
    let mut p = precondition(&r)?;
    let mut rz: Vec<f64> = r.iter().zip(&p).map(|(r, p)| dot(r, p)).collect();
    let mut done: Vec<bool> = r.iter().map(|r| r.iter().all(|&v| v == 0.0)).collect();
    for _ in 0..MAX_STEPS {
        // One pass over the matrix for every column still iterating.
        let active: Vec<usize> = (0..r.len()).filter(|&c| !done[c]).collect();
        let columns: Vec<&[f64]> = active.iter().map(|&c| &p[c][..]).collect();
        let qs = products(domain, matrix, system, &columns, &mut spread);
        for (&c, q) in active.iter().zip(qs) {
            let alpha = rz[c] / dot(&p[c], &q);
            x[c].iter_mut()
                .zip(&p[c])
                .for_each(|(x, p)| *x += alpha * p);
            r[c].iter_mut().zip(&q).for_each(|(r, q)| *r -= alpha * q);
            done[c] = converged(&r[c], &x[c], bound);
        }
        if done.iter().all(|&d| d) {
            for (z, x) in z.iter_mut().zip(&x) {
                scatter_at(system, x, z);
            }
            return Ok(true);
        }
        let y = precondition(&r)?;
        for c in (0..r.len()).filter(|&c| !done[c]) {
            let next = dot(&r[c], &y[c]);
            let beta = next / rz[c];
            rz[c] = next;
            p[c].iter_mut()
                .zip(&y[c])
                .for_each(|(p, y)| *p = y + beta * *p);
        }
    }
    Ok(false)
}

/// LAPACK's test (module doc) on the residual `r` of the solution `x`; a
/// non-finite residual never passes.
fn converged(r: &[f64], x: &[f64], bound: f64) -> bool {
    let r_max = r.iter().fold(0.0f64, |m, v| {
        if v.is_finite() {
            m.max(v.abs())
        } else {
            f64::INFINITY
        }
    });
    let x_max = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    r_max <= x_max * bound
}

/// `aᵀb`, summed in order.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// Columns [`products`] multiplies in one pass (the light pair's two, with
/// room to spare), on the stack.
const PASS_COLUMNS: usize = 4;

/// `K x` on `system` for each `x` of `xs` (in `system` order; the
/// component's unknowns outside it, its pinned pixel, are zero), up to
/// [`PASS_COLUMNS`] per pass over the matrix: reading an entry costs more
/// than the product (`Entries::get` adds the membrane), so the columns
/// share each read. Each column's sum is taken in the same order whatever
/// the others. `buffers`: domain-indexed, zero off `system`, at least as
/// many as a pass takes.
fn products(
    domain: &Domain,
    matrix: Entries,
    system: &[usize],
    xs: &[&[f64]],
    buffers: &mut [Vec<f64>],
) -> Vec<Vec<f64>> {
    let mut out = Vec::with_capacity(xs.len());
    for chunk in xs.chunks(PASS_COLUMNS) {
        let spread = &mut buffers[..chunk.len()];
        for (buffer, x) in spread.iter_mut().zip(chunk) {
            scatter_at(system, x, buffer);
        }
        let spread = &*spread;
        let sums: Vec<[f64; PASS_COLUMNS]> = system
            .par_iter()
            .map(|&k| {
                let mut sums = [0.0; PASS_COLUMNS];
                let diagonal = matrix.get(k, 0);
                for (sum, x) in sums.iter_mut().zip(spread) {
                    *sum = diagonal * x[k];
                }
                for s in 1..SLOTS.len() {
                    if let Some(j) = slot_pixel(domain, k, s) {
                        let a = matrix.get(k, s);
                        for (sum, x) in sums.iter_mut().zip(spread) {
                            *sum += a * x[j];
                        }
                    }
                    if let Some(i) = slot_source(domain, k, s) {
                        let a = matrix.get(i, s);
                        for (sum, x) in sums.iter_mut().zip(spread) {
                            *sum += a * x[i];
                        }
                    }
                }
                sums
            })
            .collect();
        out.extend((0..chunk.len()).map(|c| sums.iter().map(|row| row[c]).collect::<Vec<f64>>()));
    }
    out
}

/// `‖K‖∞`, the largest absolute row sum, on `system`.
fn matrix_norm(domain: &Domain, matrix: Entries, system: &[usize]) -> f64 {
    system
        .par_iter()
        .map(|&k| {
            let mut sum = matrix.get(k, 0).abs();
            for s in 1..SLOTS.len() {
                if slot_pixel(domain, k, s).is_some() {
                    sum += matrix.get(k, s).abs();
                }
                if let Some(i) = slot_source(domain, k, s) {
                    sum += matrix.get(i, s).abs();
                }
            }
            sum
        })
        .reduce(|| 0.0, f64::max)
}
