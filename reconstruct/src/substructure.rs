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
//! A solve of `K z = b` then uses only full solves with `M_A`, `M_B`:
//! `M_A [u; v] = [b_A; 0]` gives `g_A = K_SA K_AA⁻¹ b_A = −P_A v`;
//! `z_S = Σ⁻¹ (b_S − g_A − g_B)`; and `M_A [u; v] = [b_A; g_A + P_A z_S]` has
//! `u = z_A` (and `v = z_S`).

use crate::cholesky::{Factor, SparseCholesky};
use crate::domain::Domain;
use crate::lsq::slot_pixel;
use crate::ordering::{Ordering, bisect, fill_reducing};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use sfp_core::{Error, Result};

/// One half of the split: its interior unknowns and the separator.
struct Half {
    cholesky: SparseCholesky,
    /// Position in the half's list of each separator unknown, in separator order.
    separator_at: Vec<usize>,
}

/// The symbolic side of a split component.
pub struct Substructure {
    halves: [Half; 2],
    /// Separator unknowns (domain ids): the order of the dense blocks.
    separator: Vec<usize>,
}

impl Substructure {
    /// The split of the unknowns `members` (domain ids), or `None` when the
    /// nested-dissection cut does not apply (small or thin sets).
    pub fn new(domain: &Domain, members: &[usize]) -> Result<Option<Self>> {
        let Some([low, high, separator]) = bisect(domain, members) else {
            return Ok(None);
        };
        let (a, b) = rayon::join(
            || half(domain, &low, &separator),
            || half(domain, &high, &separator),
        );
        Ok(Some(Substructure {
            halves: [a?, b?],
            separator,
        }))
    }

    /// Bytes the numeric factors of both halves take.
    pub fn factor_bytes(&self) -> u64 {
        self.halves.iter().map(|h| h.cholesky.factor_bytes()).sum()
    }

    /// Solves `K z = b` for every right-hand side (`rhs[i]` and `z[i]` are
    /// indexed by domain unknown; only this split's unknowns are read and
    /// written), `K` in the 13-slot layout of `lsq`.
    pub fn solve(
        &self,
        domain: &Domain,
        matrix: &[[f64; 13]],
        rhs: &[Vec<f64>],
        z: &mut [Vec<f64>],
    ) -> Result<()> {
        let count = self.separator.len();
        let columns = rhs.len();
        // Factor both halves and form P = L_S L_Sᵀ on each core.
        let (a, b) = rayon::join(
            || factor_half(&self.halves[0], matrix, count),
            || factor_half(&self.halves[1], matrix, count),
        );
        let factors = [a?, b?];

        // Σ = P_A + P_B − K_SS.
        let mut schur = &factors[0].1 + &factors[1].1;
        let mut position = vec![usize::MAX; domain.len()];
        for (i, &k) in self.separator.iter().enumerate() {
            position[k] = i;
        }
        for (i, &k) in self.separator.iter().enumerate() {
            schur[(i, i)] -= matrix[k][0];
            for (s, &value) in matrix[k].iter().enumerate().skip(1) {
                if let Some(j) = slot_pixel(domain, k, s)
                    && position[j] != usize::MAX
                {
                    schur[(i, position[j])] -= value;
                    schur[(position[j], i)] -= value;
                }
            }
        }
        let schur = schur.llt(Side::Lower).map_err(|e| {
            Error::invalid(format!(
                "least-squares system is singular on the separator of a split \
                 component ({count} pixels): {e:?}"
            ))
        })?;

        // g = K_SA K_AA⁻¹ b_A = −P v with M [u; v] = [b_A; 0].
        let (a, b) = rayon::join(
            || coupling(&self.halves[0], &factors[0], rhs),
            || coupling(&self.halves[1], &factors[1], rhs),
        );
        let g = [a?, b?];
        let mut z_s = Mat::<f64>::from_fn(count, columns, |i, c| {
            rhs[c][self.separator[i]] - g[0][(i, c)] - g[1][(i, c)]
        });
        z_s = schur.solve(&z_s);

        // M [u; v] = [b_A; g + P z_S] gives u = z_A.
        let (a, b) = rayon::join(
            || interior(&self.halves[0], &factors[0], rhs, &g[0], &z_s),
            || interior(&self.halves[1], &factors[1], rhs, &g[1], &z_s),
        );
        for (half, values) in self.halves.iter().zip([a?, b?]) {
            let list = half.cholesky.list();
            for (z, values) in z.iter_mut().zip(values.chunks_exact(list.len())) {
                for (&k, &v) in list.iter().zip(values) {
                    z[k] = v;
                }
            }
        }
        for (z, column) in z.iter_mut().zip(0..columns) {
            for (i, &k) in self.separator.iter().enumerate() {
                z[k] = z_s[(i, column)];
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
    let mut position = vec![usize::MAX; domain.len()];
    for (i, &k) in list.iter().enumerate() {
        position[k] = i;
    }
    let interior = fill_reducing(Ordering::NestedDissection, domain, side)
        .expect("nested dissection gives an order");
    let separator_at: Vec<usize> = separator.iter().map(|&k| position[k]).collect();
    let elimination = interior
        .iter()
        .map(|&i| position[side[i]])
        .chain(separator_at.iter().copied())
        .collect();
    Ok(Half {
        cholesky: SparseCholesky::new(domain, list, Some(elimination), true)?,
        separator_at,
    })
}

/// The factor of a half and `P = L_S L_Sᵀ` on its separator.
fn factor_half<'a>(
    half: &'a Half,
    matrix: &[[f64; 13]],
    count: usize,
) -> Result<(Factor<'a>, Mat<f64>)> {
    let factor = half.cholesky.factor(matrix)?;
    let l = factor.trailing_block(count);
    let p = &l * l.transpose();
    Ok((factor, p))
}

/// `g = −P v` with `M [u; v] = [b_side; 0]`, one column per right-hand side.
fn coupling(half: &Half, factor: &(Factor, Mat<f64>), rhs: &[Vec<f64>]) -> Result<Mat<f64>> {
    let list = half.cholesky.list();
    let mut x: Vec<f64> = rhs
        .iter()
        .flat_map(|b| list.iter().map(|&k| b[k]))
        .collect();
    for column in x.chunks_exact_mut(list.len()) {
        for &i in &half.separator_at {
            column[i] = 0.0;
        }
    }
    factor.0.solve(&mut x)?;
    let v = Mat::<f64>::from_fn(half.separator_at.len(), rhs.len(), |i, c| {
        x[c * list.len() + half.separator_at[i]]
    });
    Ok(-(&factor.1 * &v))
}

/// The half's heights (its list order, column after column) from
/// `M [u; v] = [b_side; g + P z_S]`.
fn interior(
    half: &Half,
    factor: &(Factor, Mat<f64>),
    rhs: &[Vec<f64>],
    g: &Mat<f64>,
    z_s: &Mat<f64>,
) -> Result<Vec<f64>> {
    let list = half.cholesky.list();
    let q = g + &factor.1 * z_s;
    let mut x: Vec<f64> = rhs
        .iter()
        .flat_map(|b| list.iter().map(|&k| b[k]))
        .collect();
    for (c, column) in x.chunks_exact_mut(list.len()).enumerate() {
        for (i, &at) in half.separator_at.iter().enumerate() {
            column[at] = q[(i, c)];
        }
    }
    factor.0.solve(&mut x)?;
    Ok(x)
}
