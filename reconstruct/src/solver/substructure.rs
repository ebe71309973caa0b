//! Two-way substructuring: the normal equations of a large component are
//! split by the first nested-dissection cut into two halves `A`, `B` that do
//! not couple and the separator `S` between them, so the two halves are
//! factorised at the same time on two cores (faer's sparse Cholesky is
//! sequential over the elimination tree).
//!
//! With `K` ordered `[A, B, S]`, the halves are the principal submatrices
//! `M_A = [K_AA K_AS; K_SA K_SS]` (and `M_B`), positive definite because `K`
//! is, each factorised with `S` eliminated last. The trailing block `L_S` of
//! that factor gives `P_A = L_S L_Sᵀ = K_SS − K_SA K_AA⁻¹ K_AS`, so the Schur
//! complement of the separator is `Σ = P_A + P_B − K_SS` (dense, |S|² with
//! |S| ≈ 2 × the component's width), factorised densely.
//!
//! A solve of `K z = b` then takes one forward and one backward sweep with
//! each half's factor `L = [L_A 0; L_SA L_S]` (elimination order): the
//! forward sweep of `[b_A; 0]` gives `[y_A; y_S]` with
//! `g_A = K_SA K_AA⁻¹ b_A = −L_S y_S`; `z_S = Σ⁻¹ (b_S − g_A − g_B)`; and the
//! backward sweep of `[y_A; L_Sᵀ z_S]` gives `[z_A; z_S]`, since
//! `L_A⁻ᵀ (y_A − L_SAᵀ z_S) = K_AA⁻¹ (b_A − K_AS z_S)`. (Two full solves per
//! half, as before, read each factor twice as often: 1024² sphere, 2 right-hand
//! sides, 1.29 s of the split's 9.3 s.)

use super::slots::{Entries, SLOTS, slot_pixel};
use crate::solver::cholesky::{self, Factor, Scalar, SparseCholesky};
use crate::solver::domain::Domain;
use crate::solver::ordering::{bisect, nested_dissection};
use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::llt;
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, Par};
use sfp_core::{Error, Result};

/// One half of the split: its interior unknowns and the separator.
struct Half {
    cholesky: SparseCholesky,
    /// Position in the half's list of each separator unknown, in separator order.
    separator_at: Vec<usize>,
}

/// A half's numeric factor, its trailing block `L_S` on the separator and
/// `P = L_S L_Sᵀ`.
struct HalfFactor<'a, T> {
    factor: Factor<'a, T>,
    l: Mat<f64>,
    p: Mat<f64>,
}

/// The symbolic side of a split component.
pub struct Substructure {
    halves: [Half; 2],
    /// Separator unknowns (domain ids): the order of the dense blocks.
    separator: Vec<usize>,
    /// Couplings inside the separator, `(i, j, unknown, slot)`: `K_SS[i][j]`
    /// is slot `slot` of `unknown` (the separator's `i`-th) in the 13-slot
    /// matrix. They depend on the domain only.
    couplings: Vec<(usize, usize, usize, usize)>,
}

impl Substructure {
    /// The split of the unknowns `members` (domain ids), or `None` when the
    /// nested-dissection cut does not apply (small or thin sets).
    pub fn new(domain: &Domain, members: &[usize]) -> Result<Option<Self>> {
        let Some([low, high, mut separator]) = bisect(domain, members) else {
            return Ok(None);
        };
        // Raster order, so positions are found by binary search.
        separator.sort_unstable();
        let (a, b) = rayon::join(
            || half(domain, &low, &separator),
            || half(domain, &high, &separator),
        );
        let mut couplings = Vec::new();
        for (i, &k) in separator.iter().enumerate() {
            couplings.push((i, i, k, 0));
            for s in 1..SLOTS.len() {
                if let Some(j) = slot_pixel(domain, k, s)
                    && let Ok(p) = separator.binary_search(&j)
                {
                    couplings.push((i, p, k, s));
                }
            }
        }
        Ok(Some(Substructure {
            halves: [a?, b?],
            separator,
            couplings,
        }))
    }

    /// Bytes the numeric factors of both halves take.
    pub fn factor_bytes(&self) -> u64 {
        self.halves.iter().map(|h| h.cholesky.factor_bytes()).sum()
    }

    /// The numeric factors of `matrix` (13-slot layout of `lsq`): both halves' in
    /// precision `T`, each formed on its own core, and the separator's Schur
    /// complement.
    pub(crate) fn factor<T: Scalar>(&self, matrix: Entries) -> Result<SplitFactor<'_, T>> {
        let count = self.separator.len();
        let (a, b) = rayon::join(
            || factor_half(&self.halves[0], matrix, count),
            || factor_half(&self.halves[1], matrix, count),
        );
        let factors = [a?, b?];

        // Σ = P_A + P_B − K_SS.
        let mut schur = &factors[0].p + &factors[1].p;
        for &(i, j, k, s) in &self.couplings {
            schur[(i, j)] -= matrix.get(k, s);
            if i != j {
                schur[(j, i)] -= matrix.get(k, s);
            }
        }
        // Sequential, as every dense product here: faer's threaded kernels
        // round differently with the number of threads (the products with
        // `L_S` did: heights differed between 1 and 2 threads).
        let scratch =
            llt::factor::cholesky_in_place_scratch::<f64>(count, Par::Seq, Default::default());
        let mut scratch = cholesky::scratch(scratch)?;
        llt::factor::cholesky_in_place(
            schur.as_mut(),
            Default::default(),
            Par::Seq,
            MemStack::new(&mut scratch),
            Default::default(),
        )
        .map_err(|_| {
            Error::invalid(format!(
                "the least-squares system on {count} pixels is singular where its two \
                 halves meet: its constraints do not determine the surface there"
            ))
        })?;
        Ok(SplitFactor {
            split: self,
            factors,
            schur,
        })
    }
}

/// The numeric side of a split component ([`Substructure::factor`]).
pub struct SplitFactor<'a, T> {
    split: &'a Substructure,
    factors: [HalfFactor<'a, T>; 2],
    /// Cholesky factor of the separator's Schur complement `Σ` (its lower
    /// triangle).
    schur: Mat<f64>,
}

impl<T: Scalar> SplitFactor<'_, T> {
    /// Solves `K z = b` for every right-hand side (`rhs[i]` and `z[i]` are
    /// indexed by domain unknown; only this split's unknowns are read and
    /// written).
    pub fn solve(&self, rhs: &[Vec<f64>], z: &mut [Vec<f64>]) -> Result<()> {
        let (halves, separator) = (&self.split.halves, &self.split.separator);
        let factors = &self.factors;
        // Forward sweeps of [b_A; 0], and g = −L_S y_S.
        let (a, b) = rayon::join(
            || forward(&halves[0], &factors[0], rhs),
            || forward(&halves[1], &factors[1], rhs),
        );
        let swept = [a?, b?];
        let mut z_s = Mat::<f64>::from_fn(separator.len(), rhs.len(), |i, c| {
            rhs[c][separator[i]] - swept[0].1[(i, c)] - swept[1].1[(i, c)]
        });
        let scratch =
            llt::solve::solve_in_place_scratch::<f64>(separator.len(), rhs.len(), Par::Seq);
        let mut scratch = cholesky::scratch(scratch)?;
        llt::solve::solve_in_place(
            self.schur.as_ref(),
            z_s.as_mut(),
            Par::Seq,
            MemStack::new(&mut scratch),
        );

        // Backward sweeps of [y_A; L_Sᵀ z_S] give z_A (and z_S, written
        // exactly below).
        let [a, b] = swept;
        let (a, b) = rayon::join(
            || backward(&halves[0], &factors[0], a.0, &z_s),
            || backward(&halves[1], &factors[1], b.0, &z_s),
        );
        for (half, x) in halves.iter().zip([a?, b?]) {
            half.cholesky.scatter(&x, z);
        }
        for (c, z) in z.iter_mut().enumerate() {
            for (i, &k) in separator.iter().enumerate() {
                z[k] = z_s[(i, c)];
            }
        }
        Ok(())
    }
}

/// The half on the unknowns `side ∪ separator`: nested dissection of `side`,
/// then the separator in its given order.
fn half(domain: &Domain, side: &[usize], separator: &[usize]) -> Result<Half> {
    let mut list: Vec<usize> = side.iter().chain(separator).copied().collect();
    list.sort_unstable();
    let at = |k: &usize| list.binary_search(k).expect("a member of the list");
    let separator_at: Vec<usize> = separator.iter().map(at).collect();
    let elimination = nested_dissection(domain, side)
        .iter()
        .map(|&i| at(&side[i]))
        .chain(separator_at.iter().copied())
        .collect();
    Ok(Half {
        cholesky: SparseCholesky::new(domain, list, Some(elimination), true)?,
        separator_at,
    })
}

/// The factor of a half and `P = L_S L_Sᵀ` on its separator.
fn factor_half<'a, T: Scalar>(
    half: &'a Half,
    matrix: Entries,
    count: usize,
) -> Result<HalfFactor<'a, T>> {
    let factor = half.cholesky.factor(matrix)?;
    let l = factor.trailing_block(count);
    // `L_S` is lower triangular and `P` symmetric: the lower half of
    // `L_S L_Sᵀ` from the two triangles takes a sixth of a full product's
    // work (`|S|³/3` flops: 2 instead of 12 GFlop per half on the 1024²
    // sphere, whose separator has 1.8k unknowns), then it is mirrored.
    let mut p = Mat::<f64>::zeros(count, count);
    triangular::matmul(
        p.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        &l,
        BlockStructure::TriangularLower,
        l.transpose(),
        BlockStructure::TriangularUpper,
        1.0,
        Par::Seq,
    );
    for j in 1..count {
        for i in 0..j {
            p[(i, j)] = p[(j, i)];
        }
    }
    Ok(HalfFactor { factor, l, p })
}

/// The forward sweep of `[b_side; 0]` (elimination order, separator last)
/// and `g = −L_S y_S`, one column per right-hand side.
fn forward<T: Scalar>(
    half: &Half,
    factor: &HalfFactor<T>,
    rhs: &[Vec<f64>],
) -> Result<(Vec<f64>, Mat<f64>)> {
    let mut y = half.cholesky.gather(rhs);
    let m = half.cholesky.list().len();
    for column in y.chunks_exact_mut(m) {
        for &at in &half.separator_at {
            column[at] = 0.0;
        }
    }
    factor.factor.forward(&mut y)?;
    let count = half.separator_at.len();
    let y_s = Mat::<f64>::from_fn(count, rhs.len(), |i, c| y[c * m + m - count + i]);
    let mut g = Mat::<f64>::zeros(count, rhs.len());
    matmul(g.as_mut(), Accum::Replace, &factor.l, &y_s, -1.0, Par::Seq);
    Ok((y, g))
}

/// The half's heights (gathered layout): the backward sweep of
/// `[y_side; L_Sᵀ z_S]`.
fn backward<T: Scalar>(
    half: &Half,
    factor: &HalfFactor<T>,
    mut y: Vec<f64>,
    z_s: &Mat<f64>,
) -> Result<Vec<f64>> {
    let m = half.cholesky.list().len();
    let count = half.separator_at.len();
    let mut w = Mat::<f64>::zeros(count, z_s.ncols());
    matmul(
        w.as_mut(),
        Accum::Replace,
        factor.l.transpose(),
        z_s,
        1.0,
        Par::Seq,
    );
    for (c, column) in y.chunks_exact_mut(m).enumerate() {
        for (i, v) in column[m - count..].iter_mut().enumerate() {
            *v = w[(i, c)];
        }
    }
    factor.factor.backward(&mut y)?;
    Ok(y)
}
