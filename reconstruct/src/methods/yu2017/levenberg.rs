//! Levenberg–Marquardt on the heights, the step solved on the shared sparse
//! solver: every residual's gradient is a 3×3 stencil, so `JᵀJ` is
//! accumulated directly (`solver::lsq`), never `J`. The authors call
//! MATLAB's `lsqnonlin` (trust-region-reflective) with an iteration cap and
//! function and step tolerances; their weight schedules react to its exit
//! flag (0: the cap was hit), which [`Exit`] keeps (spec §6).
//!
//! One iteration is one accepted step `δ = −(JᵀJ + λ diag JᵀJ)⁻¹ Jᵀr`:
//! `λ` falls tenfold after a step that lowers the cost and rises tenfold
//! (the step retried) after one that does not. The cost is blind to a
//! constant height (every term reads gradients), and the solver fixes that
//! constant by giving each connected piece's step zero mean.

use crate::solver::ordered_sum::ordered_sum;
use crate::solver::domain::Domain;
use crate::solver::lsq::{NormalEquations, Solver};
use crate::solver::operators::Stencil;
use rayon::prelude::*;
use sfp_core::{Error, Result};

/// A residual and its gradient with respect to the heights.
#[derive(Clone, Copy, Debug, Default)]
pub struct Row {
    pub value: f64,
    pub gradient: Stencil,
}

impl Row {
    /// The row `weight · (value, gradient)`.
    pub fn weighted(weight: f64, value: f64, gradient: Stencil) -> Row {
        Row {
            value: weight * value,
            gradient: gradient.scaled(weight),
        }
    }
}

/// A sum of squared residuals over the heights of a domain.
pub trait Cost: Sync {
    /// Number of residuals.
    fn len(&self) -> usize;

    /// Every residual and its gradient at heights `z` (`rows.len() == len()`).
    fn evaluate(&self, z: &[f64], rows: &mut [Row]);
}

/// When [`minimise`] stops.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Accepted steps at most.
    pub iterations: usize,
    /// Stop when the cost falls by less than this times `1 + cost`.
    pub function_tolerance: f64,
    /// Stop when `‖δ‖` is below this times `1 + ‖z‖`.
    pub step_tolerance: f64,
}

/// One round of either stage, as the authors' `optimoptions` set it
/// (docs/yu2017.md: 10 steps, both tolerances 1e-4; the ratio stage's last
/// run allows more steps).
pub const ROUND: Limits = Limits {
    iterations: 10,
    function_tolerance: 1e-4,
    step_tolerance: 1e-4,
};

/// Why [`minimise`] stopped (the authors' exit flags 0, 2 and 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Exit {
    /// The iteration cap (flag 0): the schedules then update their weights.
    IterationCap,
    /// A step below the step tolerance, or no step lowered the cost (2).
    SmallStep,
    /// A reduction below the function tolerance (3).
    SmallReduction,
}

/// How a minimisation ended.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Outcome {
    pub exit: Exit,
    pub iterations: usize,
    /// Sum of squared residuals at the end.
    pub cost: f64,
}

/// Damping of the first step.
const LAMBDA_START: f64 = 1e-3;

/// Retries of a step with ten times the damping before giving up.
const RETRIES: usize = 12;

/// Minimises `cost` from heights `z` (overwritten with the result).
pub fn minimise(
    cost: &impl Cost,
    domain: &Domain,
    solver: &mut Solver,
    z: &mut [f64],
    limits: &Limits,
) -> Result<Outcome> {
    let mut rows = vec![Row::default(); cost.len()];
    let mut trial_rows = rows.clone();
    let mut trial = z.to_vec();
    cost.evaluate(z, &mut rows);
    let mut f = sum_of_squares(&rows);
    let mut lambda = LAMBDA_START;
    for iteration in 1..=limits.iterations {
        let mut base = NormalEquations::new(domain);
        let mut diagonal = vec![0.0; domain.len()];
        for row in &rows {
            base.add(&row.gradient, -row.value, 1.0);
            for (k, c) in row.gradient.entries() {
                diagonal[k] += c * c;
            }
        }
        let floor = 1e-12 * (diagonal.iter().sum::<f64>() / diagonal.len().max(1) as f64).max(1.0);
        let mut accepted = None;
        for _ in 0..RETRIES {
            let mut eq = base.clone();
            for (k, &d) in diagonal.iter().enumerate() {
                let mut s = Stencil::default();
                s.push(k, 1.0);
                eq.add(&s, 0.0, (lambda * d.max(floor)).sqrt());
            }
            let step = solver.solve(&eq)?.z.swap_remove(0);
            trial
                .par_iter_mut()
                .zip(z.par_iter().zip(&step))
                .for_each(|(t, (&zi, &di))| *t = zi + di);
            cost.evaluate(&trial, &mut trial_rows);
            let f_new = sum_of_squares(&trial_rows);
            if !f_new.is_finite() {
                return Err(Error::invalid("yu2017: the cost is not finite"));
            }
            if f_new < f {
                lambda = (lambda / 10.0).max(1e-12);
                accepted = Some((step, f_new));
                break;
            }
            lambda *= 10.0;
        }
        let Some((step, f_new)) = accepted else {
            return Ok(Outcome {
                exit: Exit::SmallStep,
                iterations: iteration,
                cost: f,
            });
        };
        let reduction = f - f_new;
        z.copy_from_slice(&trial);
        std::mem::swap(&mut rows, &mut trial_rows);
        f = f_new;
        let exit = if reduction < limits.function_tolerance * (1.0 + f + reduction) {
            Some(Exit::SmallReduction)
        } else if norm(&step) < limits.step_tolerance * (1.0 + norm(z)) {
            Some(Exit::SmallStep)
        } else {
            None
        };
        if let Some(exit) = exit {
            return Ok(Outcome {
                exit,
                iterations: iteration,
                cost: f,
            });
        }
    }
    Ok(Outcome {
        exit: Exit::IterationCap,
        iterations: limits.iterations,
        cost: f,
    })
}

/// Checks every row's gradient of `cost` at `z` against central
/// differences of its values (relative tolerance `tol`).
#[cfg(test)]
pub fn assert_gradients(cost: &impl Cost, z: &[f64], tol: f64) {
    let mut rows = vec![Row::default(); cost.len()];
    cost.evaluate(z, &mut rows);
    let (mut plus, mut minus) = (rows.clone(), rows.clone());
    let h = 1e-6;
    let mut checked = 0;
    for k in 0..z.len() {
        let mut zp = z.to_vec();
        zp[k] += h;
        cost.evaluate(&zp, &mut plus);
        zp[k] -= 2.0 * h;
        cost.evaluate(&zp, &mut minus);
        for (i, row) in rows.iter().enumerate() {
            let numeric = (plus[i].value - minus[i].value) / (2.0 * h);
            let analytic: f64 = row.gradient.entries().filter(|e| e.0 == k).map(|e| e.1).sum();
            let scale = 1.0 + numeric.abs().max(analytic.abs());
            assert!(
                (numeric - analytic).abs() < tol * scale,
                "row {i}, unknown {k}: analytic {analytic}, numeric {numeric}"
            );
            checked += usize::from(numeric != 0.0);
        }
    }
    assert!(checked > z.len(), "only {checked} non-zero derivatives");
}

fn sum_of_squares(rows: &[Row]) -> f64 {
    ordered_sum(rows.len(), |i| rows[i].value * rows[i].value)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::ordering::Ordering;
    use sfp_core::Mask;

    /// Residuals `g(z_right − z) − 1` and `g(z_below − z)` with the
    /// nonlinear `g(d) = d + d³/10`: a plane rising
    /// `g⁻¹(1)` per pixel to the right.
    struct Plane {
        domain: Domain,
    }

    impl Cost for Plane {
        fn len(&self) -> usize {
            2 * self.domain.len()
        }
        fn evaluate(&self, z: &[f64], rows: &mut [Row]) {
            for (k, pair) in rows.chunks_mut(2).enumerate() {
                let (x, y) = self.domain.pixel(k);
                for (r, (dx, dy, want)) in pair.iter_mut().zip([(1, 0, 1.0), (0, 1, 0.0)]) {
                    *r = match self.domain.at(x as isize + dx, y as isize + dy) {
                        Some(j) => {
                            let mut s = Stencil::default();
                            s.push(j, 1.0);
                            s.push(k, -1.0);
                            let d = z[j] - z[k];
                            let value = d + 0.1 * d * d * d - want;
                            Row::weighted(1.0, value, s.scaled(1.0 + 0.3 * d * d))
                        }
                        None => Row::default(),
                    };
                }
            }
        }
    }

    #[test]
    fn converges_on_a_small_nonlinear_problem() {
        let domain = Domain::new(&Mask::new(6, 5, true));
        let cost = Plane { domain: domain.clone() };
        let mut z: Vec<f64> = (0..domain.len()).map(|k| 0.3 * (k % 7) as f64).collect();
        let mut solver = Solver::new(Ordering::default());
        let limits = Limits {
            iterations: 100,
            function_tolerance: 1e-14,
            step_tolerance: 1e-14,
        };
        let out = minimise(&cost, &domain, &mut solver, &mut z, &limits).unwrap();
        assert!(out.cost < 1e-10, "{out:?}");
        assert_ne!(out.exit, Exit::IterationCap);
        let (a, b) = (domain.at(0, 0).unwrap(), domain.at(1, 0).unwrap());
        let d = z[b] - z[a];
        assert!((d + 0.1 * d * d * d - 1.0).abs() < 1e-5);
        // A cap of one step stops with the cap's flag.
        let mut z: Vec<f64> = (0..domain.len()).map(|k| 0.3 * (k % 7) as f64).collect();
        let one = Limits { iterations: 1, ..limits };
        let out = minimise(&cost, &domain, &mut solver, &mut z, &one).unwrap();
        assert_eq!((out.exit, out.iterations), (Exit::IterationCap, 1));
    }
}
