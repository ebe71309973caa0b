//! Sparse Cholesky factorisation (faer) of the normal matrix of `lsq`
//! restricted to a set of unknowns: a whole connected component, or one half
//! of a split component (`substructure`).
//!
//! The matrix comes in the 13-slot layout of `lsq` (the diagonal and the 12
//! couplings to pixels later in raster order). The set is kept in raster
//! order, so those couplings are exactly the lower triangle faer reads; the
//! elimination order is separate (a fill-reducing permutation).

use super::slots::{Entries, SLOTS, slot_pixel};
use crate::solver::domain::{Domain, scatter_at};
use crate::solver::memory;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::traits::RealField;
use faer::{Conj, Mat, MatMut, Par, Side};
use sfp_core::{Error, Result};

/// The precision a numeric factor is kept in: `f64`, or `f32` for the large
/// systems `mixed` solves by refinement.
pub trait Scalar: RealField + Copy {
    fn from_f64(v: f64) -> Self;
    fn to_f64(self) -> f64;
}

impl Scalar for f64 {
    fn from_f64(v: f64) -> Self {
        v
    }
    fn to_f64(self) -> f64 {
        self
    }
}

impl Scalar for f32 {
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

/// faer's threads for the numeric factorisation and solves: none. On these
/// image systems the supernodes are too small for faer's parallel dense
/// kernels to pay off and the rayon workers only contend, worst on a busy
/// machine (512² integration system on 2 cores: 0.90 s sequential vs 1.10 s
/// with `Par::rayon(2)` quiet; under load ~3 worse still). The two cores are
/// used one level up instead, on the two halves of a split (`substructure`).
const PARALLELISM: Par = Par::Seq;

/// The symbolic factorisation of the normal matrix on a set of unknowns.
pub struct SparseCholesky {
    /// Domain unknowns of the system in raster order (the matrix order).
    list: Vec<usize>,
    /// The lower triangle's pattern (columns in `list` order), in 32-bit
    /// indices, as faer's symbolic and numeric factors keep theirs: half
    /// the bytes of `usize` (the checks in [`Self::new`] keep them in range).
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    /// Where each stored entry comes from in the 13-slot matrix, flattened:
    /// `13 · unknown + slot` (4 bytes instead of a pair's 16: at 13 entries
    /// per unknown, 156 bytes per pixel of a system).
    source: Vec<u32>,
    symbolic: SymbolicCholesky<u32>,
}

impl SparseCholesky {
    /// The symbolic factorisation for the unknowns `list` (ascending, i.e. raster order,
    /// couplings to unknowns outside it are dropped), eliminated in the
    /// order `elimination` (positions in `list`), or by faer's AMD when
    /// `None`. `supernodal` forces the supernodal layout
    /// [`Self::trailing_block`] reads.
    pub fn new(
        domain: &Domain,
        list: Vec<usize>,
        elimination: Option<Vec<usize>>,
        supernodal: bool,
    ) -> Result<Self> {
        let m = list.len();
        debug_assert!(list.is_sorted(), "the list must be in raster order");
        if domain.len() * SLOTS.len() > u32::MAX as usize {
            return Err(Error::invalid(format!(
                "a mask of {} pixels is too large for the sparse Cholesky solver (at most {})",
                domain.len(),
                u32::MAX as usize / SLOTS.len()
            )));
        }
        // Position of the later unknown `j` coupled to `list[i] = k`: ids
        // grow by at least one per member, so it lies within `j − k` places
        // (no domain-sized map per system: a mask of many small components
        // would pay for the whole image each time).
        let position = |i: usize, k: usize, j: usize| {
            let window = &list[i + 1..(i + 1 + j - k).min(m)];
            window.binary_search(&j).ok().map(|p| i + 1 + p)
        };
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut row_idx = Vec::with_capacity(m * SLOTS.len());
        let mut source = Vec::with_capacity(m * SLOTS.len());
        col_ptr.push(0);
        for (i, &k) in list.iter().enumerate() {
            row_idx.push(i as u32);
            source.push(flat(k, 0));
            for s in 1..SLOTS.len() {
                if let Some(p) = slot_pixel(domain, k, s).and_then(|j| position(i, k, j)) {
                    row_idx.push(p as u32);
                    source.push(flat(k, s));
                }
            }
            col_ptr.push(row_idx.len() as u32);
        }
        let perm = elimination.map(|order| {
            let mut inverse = vec![0u32; m];
            for (new, &old) in order.iter().enumerate() {
                inverse[old] = new as u32;
            }
            let order: Vec<u32> = order.into_iter().map(|i| i as u32).collect();
            faer::perm::Perm::new_checked(order.into_boxed_slice(), inverse.into_boxed_slice(), m)
        });
        let ordering = match &perm {
            Some(p) => SymmetricOrdering::Custom(p.as_ref()),
            None => SymmetricOrdering::Amd,
        };
        let mut params = CholeskySymbolicParams::default();
        if supernodal {
            params.supernodal_flop_ratio_threshold = SupernodalThreshold::FORCE_SUPERNODAL;
        }
        let pattern = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, ordering, params)
            .map_err(|e| {
                Error::invalid(format!(
                    "the sparse Cholesky factorisation of {m} unknowns could not be prepared ({e})"
                ))
            })?;
        Ok(SparseCholesky {
            list,
            col_ptr,
            row_idx,
            source,
            symbolic,
        })
    }

    /// Unknowns of the system, in matrix (raster) order.
    pub fn list(&self) -> &[usize] {
        &self.list
    }

    /// The right-hand sides (each indexed by domain unknown) restricted to
    /// this system: `list` order, column after column, as [`Factor::solve`]
    /// takes them.
    pub fn gather(&self, rhs: &[Vec<f64>]) -> Vec<f64> {
        rhs.iter()
            .flat_map(|b| self.list.iter().map(move |&k| b[k]))
            .collect()
    }

    /// Writes solved columns (the layout of [`Self::gather`]) into `z`.
    pub fn scatter(&self, x: &[f64], z: &mut [Vec<f64>]) {
        for (z, column) in z.iter_mut().zip(x.chunks_exact(self.list.len())) {
            scatter_at(&self.list, column, z);
        }
    }

    /// Bytes the numeric factor takes.
    pub fn factor_bytes(&self) -> u64 {
        self.symbolic.len_val() as u64 * 8
    }

    /// The numeric factor of `matrix` on this set, in precision `T`.
    pub(crate) fn factor<T: Scalar>(&self, matrix: Entries) -> Result<Factor<'_, T>> {
        let m = self.list.len();
        let values: Vec<T> = self
            .source
            .iter()
            .map(|&e| {
                let (k, s) = unflat(e);
                T::from_f64(matrix.get(k, s))
            })
            .collect();
        let pattern =
            SymbolicSparseColMatRef::new_checked(m, m, &self.col_ptr, None, &self.row_idx);
        let len = self.symbolic.len_val();
        // Reserved first so that a factor too large is an error, not an
        // abort; then allocated zeroed, as fresh pages from the system: faer
        // writes every entry itself, and filling the factor here as well was
        // a second pass over it (512² sphere: 1.6% of SMSfP's instructions).
        Vec::<T>::new().try_reserve_exact(len).map_err(|_| {
            Error::invalid(format!(
                "out of memory for the Cholesky factor of {m} pixels ({:.1} GB): \
                 use a smaller image or mask",
                (len * size_of::<T>()) as f64 * 1e-9
            ))
        })?;
        let mut factor = vec![T::from_f64(0.0); len];
        let mut scratch = scratch(
            self.symbolic
                .factorize_numeric_llt_scratch::<T>(PARALLELISM, Default::default()),
        )?;
        self.symbolic
            .factorize_numeric_llt(
                &mut factor,
                SparseColMatRef::new(pattern, &values),
                Side::Lower,
                Default::default(),
                PARALLELISM,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .map_err(|_| {
                Error::invalid(format!(
                    "the least-squares system on {m} pixels is singular: its constraints \
                     do not determine the surface (pixels without polarization signal \
                     or shading? a larger --lambda smooths over them)"
                ))
            })?;
        Ok(Factor {
            cholesky: self,
            values: factor,
        })
    }
}

/// The flattened position of slot `s` of unknown `k` in a 13-slot matrix
/// (`SparseCholesky::new` checks that it fits).
fn flat(k: usize, s: usize) -> u32 {
    (k * SLOTS.len() + s) as u32
}

/// The unknown and slot of a [`flat`] position.
fn unflat(e: u32) -> (usize, usize) {
    let e = e as usize;
    (e / SLOTS.len(), e % SLOTS.len())
}

/// A numeric factor `L Lᵀ` of the matrix of a [`SparseCholesky`], in
/// precision `T`; its solves take and give `f64`.
pub struct Factor<'a, T> {
    cholesky: &'a SparseCholesky,
    values: Vec<T>,
}

impl<T: Scalar> Factor<'_, T> {
    /// Solves in place for the columns of `rhs` (`list` order, column-major,
    /// `list.len()` rows).
    pub fn solve(&self, rhs: &mut [f64]) -> Result<()> {
        let symbolic = &self.cholesky.symbolic;
        let m = self.cholesky.list.len();
        let columns = rhs.len() / m.max(1);
        let mut scratch = scratch(symbolic.solve_in_place_scratch::<T>(columns, PARALLELISM))?;
        let mut x: Vec<T> = rhs.iter().map(|&v| T::from_f64(v)).collect();
        LltRef::<'_, u32, T>::new(symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut x, m, columns),
            PARALLELISM,
            MemStack::new(&mut scratch),
        );
        for (r, v) in rhs.iter_mut().zip(x) {
            *r = v.to_f64();
        }
        Ok(())
    }

    /// The forward sweep `y = L⁻¹ Pᵀ b` for the columns of `rhs` (`list`
    /// order, as [`Self::solve`] takes them); `y` is in elimination order.
    /// With [`Self::backward`] it is [`Self::solve`] split in its two
    /// halves, so a caller can change the trailing part of `y` in between.
    pub fn forward(&self, rhs: &mut [f64]) -> Result<()> {
        self.sweep(rhs, Sweep::Forward)
    }

    /// The backward sweep `x = P L⁻ᵀ y` for the columns of `y` (elimination
    /// order, as [`Self::forward`] leaves them); `x` is in `list` order.
    pub fn backward(&self, y: &mut [f64]) -> Result<()> {
        self.sweep(y, Sweep::Backward)
    }

    fn sweep(&self, rhs: &mut [f64], sweep: Sweep) -> Result<()> {
        let symbolic = &self.cholesky.symbolic;
        let SymbolicCholeskyRaw::Supernodal(supernodal) = symbolic.raw() else {
            panic!("sweeps need a supernodal factorisation (SparseCholesky::new)");
        };
        let m = self.cholesky.list.len();
        let columns = rhs.len() / m.max(1);
        let (order, _) = symbolic
            .perm()
            .expect("a custom elimination order")
            .arrays();
        let mut scratch = scratch(symbolic.solve_in_place_scratch::<T>(columns, PARALLELISM))?;
        let stack = MemStack::new(&mut scratch);
        let factor = SupernodalLltRef::new(supernodal, &self.values);
        match sweep {
            Sweep::Forward => {
                let mut y = vec![T::from_f64(0.0); rhs.len()];
                for (to, from) in y.chunks_exact_mut(m).zip(rhs.chunks_exact(m)) {
                    for (t, &old) in to.iter_mut().zip(order) {
                        *t = T::from_f64(from[old as usize]);
                    }
                }
                let view = MatMut::from_column_major_slice_mut(&mut y, m, columns);
                factor.l_solve_with_conj(Conj::No, view, PARALLELISM, stack);
                for (r, v) in rhs.iter_mut().zip(y) {
                    *r = v.to_f64();
                }
            }
            Sweep::Backward => {
                let mut y: Vec<T> = rhs.iter().map(|&v| T::from_f64(v)).collect();
                let view = MatMut::from_column_major_slice_mut(&mut y, m, columns);
                factor.l_transpose_solve_with_conj(Conj::No, view, PARALLELISM, stack);
                for (to, from) in rhs.chunks_exact_mut(m).zip(y.chunks_exact(m)) {
                    for (&v, &old) in from.iter().zip(order) {
                        to[old as usize] = v.to_f64();
                    }
                }
            }
        }
        Ok(())
    }

    /// The dense lower-triangular block of `L` on the last `count`
    /// eliminated unknowns. Its `L Lᵀ` is the matrix on those unknowns minus
    /// the coupling through all the others (their Schur complement).
    pub fn trailing_block(&self, count: usize) -> Mat<f64> {
        let SymbolicCholeskyRaw::Supernodal(symbolic) = self.cholesky.symbolic.raw() else {
            panic!("trailing_block needs a supernodal factorisation (SparseCholesky::new)");
        };
        let factor = SupernodalLltRef::new(symbolic, &self.values);
        let first = symbolic.nrows() - count;
        let mut block = Mat::<f64>::zeros(count, count);
        for s in 0..symbolic.n_supernodes() {
            let node = factor.supernode(s);
            let (start, values, pattern) = (node.start(), node.val(), node.pattern());
            let width = values.ncols();
            for c in (0..width).filter(|&c| start + c >= first) {
                let col = start + c - first;
                for r in c..width {
                    block[(start + r - first, col)] = values[(r, c)].to_f64();
                }
                for (i, &row) in pattern.iter().enumerate() {
                    block[(row as usize - first, col)] = values[(width + i, c)].to_f64();
                }
            }
        }
        block
    }
}

/// Which triangular sweep [`Factor::sweep`] runs.
enum Sweep {
    Forward,
    Backward,
}

/// faer's workspace for `req`, allocated fallibly: too large a problem is
/// an error saying how much it needed.
pub(super) fn scratch(req: faer::dyn_stack::StackReq) -> Result<MemBuffer> {
    MemBuffer::try_new(req).map_err(|_| {
        Error::memory(format!(
            "out of memory: a Cholesky workspace needs {:.1} MB",
            req.size_bytes() as f64 * 1e-6
        ))
    })
}

/// Refuses a factorisation whose factor alone needs more memory than is
/// available (`memory::available`: the system's memory and the address
/// space left; elsewhere no check), with a message a user can act on,
/// instead of being killed for lack of memory.
pub fn check_memory(bytes: u64, pixels: usize) -> Result<()> {
    // Small factors never are the problem; a mask of thousands of small
    // components must not read /proc thousands of times.
    if bytes < SMALL_FACTOR {
        return Ok(());
    }
    let Some(available) = memory::available() else {
        return Ok(());
    };
    if bytes <= available {
        return Ok(());
    }
    Err(Error::memory(format!(
        "out of memory: the least-squares system of {pixels} pixels needs {:.1} GB for its \
         Cholesky factor but {:.1} GB of memory is available: use a smaller image (e.g. \
         super-pixel demosaicing) or a mask",
        bytes as f64 * 1e-9,
        available as f64 * 1e-9
    )))
}

/// Factors below this many bytes are not checked against the available memory.
const SMALL_FACTOR: u64 = 256 << 20;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_singular_system_is_explained_not_shown_as_solver_internals() {
        // Three pixels in a row with a zero normal matrix: nothing constrains
        // the heights.
        let mask = sfp_core::Mask::from_fn(3, 1, |_, _| true);
        let domain = Domain::new(&mask);
        let chol = SparseCholesky::new(&domain, (0..3).collect(), None, false).unwrap();
        let e = chol
            .factor::<f64>(Entries::new(&[[0.0; 13]; 3], &domain))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("singular") && e.contains("3 pixels"), "{e}");
        assert!(!e.contains("Pivot") && !e.contains('{'), "{e}");
    }

    #[test]
    fn memory_check_refuses_what_cannot_fit() {
        assert!(check_memory(1 << 20, 100).is_ok());
        if memory::available().is_some() {
            let e = check_memory(u64::MAX / 2, 5_000_000)
                .unwrap_err()
                .to_string();
            assert!(e.contains("5000000 pixels") && e.contains("GB"), "{e}");
        }
    }
}
