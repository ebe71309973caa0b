//! How one component's system is factorised ([`Plan`]: whole, or split in
//! two halves and a separator on two cores) and in which precision
//! ([`Precision`]): `lsq`'s solver keeps a plan per set of unknowns.

use super::mixed::refine;
use super::slots::Entries;
use crate::solver::cholesky::{Factor, Scalar, SparseCholesky};
use crate::solver::domain::Domain;
use crate::solver::substructure::{SplitFactor, Substructure};
use sfp_core::Result;

/// Membrane weight, relative to the mean diagonal, of the single-precision
/// factor tried when one without it fails ([`Precision::Floored`]). The
/// fruit capture's height-from-polarization systems keep modes that only a
/// weight below 1e-5 holds (not traced; likely bands where the AoP row and
/// the shading row constrain one direction, leaving the other to the
/// smoothness term's `λ² k⁴`): their single-precision factor fails with a
/// floor of 1e-6 and not with 1e-5. (A few pixels without rows, which the
/// membrane alone holds, do not make it fail: nothing cancels in their
/// rows.) The floor only shapes the preconditioner; conjugate gradients
/// solve the true system. Refinement steps on the 1224×1024 capture: 15
/// with 1e-5, 10 with 1e-4, 8 with 1e-3 (the analytic sphere, which needs
/// no floor: 4 without it, 6 with 1e-5).
pub(super) const FLOOR: f64 = 1e-4;

/// Systems from this many unknowns on try [`Precision::Floored`] before
/// double precision: it saves memory (half the factor), and time on the
/// largest systems. The 5 MP fruit capture (components of 0.97 M and 1.54 M
/// unknowns): Smith 23.1 s and 5.46 GB in double → 20.2 s and 4.17 GB with
/// both floored, 19.6 s and 4.19 GB with the larger alone; SMSfP 70 s and
/// 5.8 GB → 62.8 s and 4.32 GB, 60.2 s and 4.43 GB. Below a million the
/// double factor is faster (the 1224×1024 capture's 646k unknowns: Smith
/// 4.7 s and 1.86 GB in double, 5.6 s and 1.32 GB floored).
pub(super) const FLOORED_MIN: usize = 1_000_000;

/// How one component's system is factorised.
pub(super) enum Plan {
    Whole(Box<SparseCholesky>),
    Split(Box<Substructure>),
}

impl Plan {
    /// Bytes the numeric factor(s) take.
    pub(super) fn factor_bytes(&self) -> u64 {
        match self {
            Plan::Whole(cholesky) => cholesky.factor_bytes(),
            Plan::Split(substructure) => substructure.factor_bytes(),
        }
    }

    /// Solves the system of `matrix` (13-slot layout) on the unknowns
    /// `system` for every right-hand side, writing them in `z`: by the
    /// single-precision factors of `singles` in turn (`Single`, `Floored`),
    /// the first that factorises and refines, else in double; returns the
    /// precision that solved it.
    pub(super) fn solve(
        &self,
        domain: &Domain,
        matrix: Entries,
        system: &[usize],
        singles: &[Precision],
        rhs: &[Vec<f64>],
        z: &mut [Vec<f64>],
    ) -> Result<Precision> {
        for &precision in singles {
            let entries = if precision == Precision::Floored {
                let mean =
                    system.iter().map(|&k| matrix.get(k, 0)).sum::<f64>() / system.len() as f64;
                matrix.with_membrane(FLOOR * mean)
            } else {
                matrix
            };
            let factor = self.factor::<f32>(entries);
            if let Ok(single) = factor
                && refine(domain, matrix, system, rhs, z, |b, x| single.solve(b, x))?
            {
                return Ok(precision);
            }
        }
        self.factor::<f64>(matrix)?.solve(rhs, z)?;
        Ok(Precision::Double)
    }

    /// The numeric factor(s) of `matrix` in precision `T`.
    fn factor<T: Scalar>(&self, matrix: Entries) -> Result<Numeric<'_, T>> {
        Ok(match self {
            Plan::Whole(cholesky) => Numeric::Whole(cholesky, cholesky.factor(matrix)?),
            Plan::Split(substructure) => Numeric::Split(Box::new(substructure.factor(matrix)?)),
        })
    }
}

/// The numeric side of a [`Plan`].
enum Numeric<'a, T> {
    Whole(&'a SparseCholesky, Factor<'a, T>),
    Split(Box<SplitFactor<'a, T>>),
}

impl<T: Scalar> Numeric<'_, T> {
    /// Solves for every right-hand side (indexed by domain unknown), writing
    /// the system's unknowns of `z`.
    fn solve(&self, rhs: &[Vec<f64>], z: &mut [Vec<f64>]) -> Result<()> {
        match self {
            Numeric::Whole(cholesky, factor) => {
                let mut x = cholesky.gather(rhs);
                factor.solve(&mut x)?;
                cholesky.scatter(&x, z);
                Ok(())
            }
            Numeric::Split(split) => split.solve(rhs, z),
        }
    }
}

/// How a system is factorised, in the order tried (`mixed`): a single-
/// precision factor refined to double by conjugate gradients; the same with
/// the membrane raised to [`FLOOR`] in the factor only, for systems whose
/// weakest modes are below single precision's reach (the fruit capture's,
/// at 1224×1024 and at 5 MP; rows that leave modes only the membrane holds
/// do that, tests below); a double-precision factor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Precision {
    Single,
    Floored,
    Double,
}
