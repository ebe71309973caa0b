//! Geometric multigrid on the bounding box of a masked grid: the
//! preconditioner of the conjugate-gradient solver (`conjugate_gradient`).
//!
//! The finest level is the pixels' rectangle stored with a zero border of
//! [`PAD`] pixels, holding the symmetric operator in the 13-slot upper
//! layout of `slots` as 13 planes (one per slot, structure of arrays, so a
//! product streams through memory in straight runs the compiler
//! vectorises). Pixels outside the mask have zero rows: they never move.
//!
//! Why the coarse levels carry four unknowns per node: every method's rows
//! use the smoothed central differences of `operators`, whose Fourier
//! symbol `i sin ω_x (2 + cos ω_y) / 3` vanishes at `ω_x = π` as well as
//! at 0. `A = D_xᵀD_x + D_yᵀD_y` therefore has four valleys of small
//! eigenvalues, at `(0, 0)`, `(π, 0)`, `(0, π)` and `(π, π)` (near
//! `(π, 0)` its symbol is `a² + b²/9`): besides the smooth modes, the smooth
//! modes times `(−1)^x`, `(−1)^y` and `(−1)^(x+y)` are nearly free (only
//! the mask edge's one-sided differences and other rows tie them).
//! Gauss–Seidel leaves all four valleys, and a bilinear coarse grid
//! represents only the first, so a hierarchy of single pixels needed 132,
//! 194 and more than 300 iterations on the sphere's integration system at
//! 256², 512² and 1024². Here a level-1 node instead stands for a 2×2
//! block of pixel pairs: the pixels of one parity class `(x mod 2,
//! y mod 2)` form a grid of their own (on which all four valleys are
//! smooth), and each class is interpolated bilinearly from every other of
//! its pixels, as the component of that class of the coarse node. So the
//! coarse space holds every smooth function times each of the four
//! carriers, and the same system takes 8 iterations at every size
//! (with the diagonal of [`Level`] in double precision; 12, 8 and 12
//! without). (`integrate` now adds compact differences, which lift the
//! three aliasing valleys: its system of the sphere takes 5, 5 and 6.)
//! The levels below
//! coarsen every component alike (`Blocks`); a node couples to its 8
//! neighbours by 4×4 blocks, since fine couplings reach 2 pixels, one
//! node of a parity grid.
//!
//! What it does not cure: the height-from-polarization system (both light
//! candidates of the 256², 512², 1024² spheres) still takes 61, 91 and 139
//! iterations (the single-pixel hierarchy: 45, 69, 132; slower than
//! factorising). Its AoP rows fix only the derivative across the AoP
//! direction; along it only the weak shading rows and the Laplacian hold
//! the surface (without shading rows 232 iterations at 256², with λ = 0 no
//! convergence), an anisotropy that follows the AoP field and that neither
//! coarse space nor point smoothing resolves (row and column line
//! Gauss–Seidel on the finest level, tried with a single-precision
//! diagonal: 70 and 60 iterations at 256² with 1 and 2 sweeps, against 82).
//!
//! The interpolation `P` is bilinear on each component (weights 1, ½, ¼;
//! they sum to 1 at every fine node, so constants, the operator's null
//! space on each connected piece, are interpolated exactly) and the coarse
//! operator is Galerkin's `Pᵀ A P`.
//!
//! One V-cycle: forward Gauss–Seidel sweeps (on the coarse levels, all
//! four components of a node at once), the coarse correction, then as many
//! backward sweeps, so the cycle is a symmetric operator, as conjugate
//! gradients needs (the order is in [`Level::gauss_seidel`]). The coarsest
//! level (at most [`COARSEST`] nodes) is solved with the pseudo-inverse of
//! its dense matrix: it stays singular (one constant per piece of the mask).

use super::slots::{SLOTS, slot};
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{ComputeEigenvectors, self_adjoint_evd, self_adjoint_evd_scratch};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use rayon::prelude::*;

/// Zero border around every level, the reach of the operator's couplings.
pub(crate) const PAD: usize = 2;

/// Coarsening stops once a level has at most this many nodes (4 unknowns
/// each, solved densely).
const COARSEST: usize = 64;

/// Gauss–Seidel sweeps before and after the coarse correction, on every
/// level (4 on the finest and 6 below cut the 512² sphere's integration
/// from 8 to 6 iterations but took 1.07 s instead of 0.61 s, measured
/// before the diagonal was kept in double precision).
const SWEEPS: usize = 2;

/// Elements per parallel chunk of a grid product.
const CHUNK: usize = 1 << 14;

/// A rectangle of pixels stored row by row with a border of [`PAD`] pixels.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grid {
    pub width: usize,
    pub height: usize,
    stride: usize,
}

impl Grid {
    pub fn new(width: usize, height: usize) -> Self {
        Grid {
            width,
            height,
            stride: width + 2 * PAD,
        }
    }

    /// Elements of a vector on the grid, border included.
    pub fn len(&self) -> usize {
        self.stride * (self.height + 2 * PAD)
    }

    /// Storage index of pixel `(x, y)` (`-PAD <= x < width + PAD`, same for `y`).
    #[inline]
    pub fn at(&self, x: isize, y: isize) -> usize {
        ((y + PAD as isize) * self.stride as isize + x + PAD as isize) as usize
    }

    /// Storage distance of the pixel offset `(dx, dy)`.
    #[inline]
    fn offset(&self, dx: isize, dy: isize) -> isize {
        dy * self.stride as isize + dx
    }

    /// Storage range every product covers: the pixels and the border columns
    /// between rows (whose rows are zero), never closer than the operator's
    /// reach to either end.
    fn interior(&self) -> std::ops::Range<usize> {
        PAD * self.stride + PAD..(self.height + PAD) * self.stride - PAD
    }

    /// Storage offsets of the 13 upper slots (all positive).
    fn slot_offsets(&self) -> [usize; 13] {
        SLOTS.map(|(dx, dy)| self.offset(dx, dy) as usize)
    }
}

/// Storage type of the operator's coefficients.
type Coefficient = f32;

/// One level: the operator on a grid.
pub(crate) struct Level {
    pub grid: Grid,
    /// `upper[s][i]`: coupling of pixel `i` with the pixel at slot `s ≥ 1`,
    /// in single precision (half the memory traffic; the products
    /// accumulate in double precision); `upper[0]` is empty.
    upper: Vec<Vec<Coefficient>>,
    /// The diagonal, in double precision and corrected for the rounding of
    /// the couplings, so that the rows still sum to what they summed to:
    /// the normal equations' rows sum to zero, and with rounded couplings
    /// alone every piece's constant would become a mode of eigenvalue
    /// ~1e-7 of the diagonal, of either sign, which conjugate gradients
    /// stalled on (a 2.5 M-pixel capture's integration: the residual fell to
    /// 3e-6 in 100 iterations, then rose again).
    diagonal: Vec<f64>,
}

impl Level {
    /// The level of `upper` (13 planes on `grid`, double precision).
    pub fn new(grid: Grid, upper: Vec<Vec<f64>>) -> Self {
        debug_assert!(upper.len() == 13 && upper.iter().all(|p| p.len() == grid.len()));
        let offsets = grid.slot_offsets();
        let rounded: Vec<Vec<Coefficient>> = upper
            .iter()
            .enumerate()
            .map(|(s, plane)| match s {
                0 => Vec::new(),
                _ => plane.iter().map(|&v| v as Coefficient).collect(),
            })
            .collect();
        // Each coupling's rounding error, moved onto both its pixels' diagonal.
        let error = |s: usize, i: usize| upper[s][i] - f64::from(rounded[s][i]);
        let mut diagonal = upper[0].clone();
        diagonal.par_iter_mut().enumerate().for_each(|(i, d)| {
            for (s, &off) in offsets.iter().enumerate().skip(1) {
                if i + off < grid.len() {
                    *d += error(s, i);
                }
                if i >= off {
                    *d += error(s, i - off);
                }
            }
        });
        Level {
            grid,
            upper: rounded,
            diagonal,
        }
    }

    /// Coefficient between storage index `p` and the pixel `(dx, dy)` from it.
    #[inline]
    fn coefficient(&self, p: usize, dx: isize, dy: isize) -> f64 {
        if dx == 0 && dy == 0 {
            self.diagonal[p]
        } else if dy > 0 || (dy == 0 && dx > 0) {
            f64::from(self.upper[slot(dx, dy)][p])
        } else {
            let q = (p as isize + self.grid.offset(dx, dy)) as usize;
            f64::from(self.upper[slot(-dx, -dy)][q])
        }
    }

    /// `out = b − A x` (`b = None`: `out = A x`), in parallel chunks.
    pub fn residual(&self, b: Option<&[f64]>, x: &[f64], out: &mut [f64]) {
        let range = self.grid.interior();
        let offsets = self.grid.slot_offsets();
        out[range.clone()]
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, out)| {
                let start = range.start + c * CHUNK;
                let n = out.len();
                let diagonal = &self.diagonal[start..start + n];
                for ((o, &d), &v) in out.iter_mut().zip(diagonal).zip(&x[start..start + n]) {
                    *o = d * v;
                }
                for (s, &off) in offsets.iter().enumerate().skip(1) {
                    let plane = &self.upper[s];
                    let forward = plane[start..start + n]
                        .iter()
                        .zip(&x[start + off..start + off + n]);
                    let backward = plane[start - off..start - off + n]
                        .iter()
                        .zip(&x[start - off..start - off + n]);
                    for ((o, (&uf, &xf)), (&ub, &xb)) in out.iter_mut().zip(forward).zip(backward) {
                        *o += f64::from(uf) * xf + f64::from(ub) * xb;
                    }
                }
                if let Some(b) = b {
                    for (o, &b) in out.iter_mut().zip(&b[start..start + n]) {
                        *o = b - *o;
                    }
                }
            });
    }

    /// One Gauss–Seidel sweep on `A x = b` (`scratch`: a vector on the
    /// grid). Rows are visited in three classes by `y mod 3`: rows of one
    /// class do not couple (couplings reach 2 rows), so they are relaxed in
    /// parallel, each first against the other rows at once, then pixel by
    /// pixel along the row. `forward`: classes 0, 1, 2 and each row left to
    /// right; otherwise the exact reverse, so a forward sweep before the
    /// coarse correction and a backward one after it make the cycle
    /// symmetric.
    fn gauss_seidel(&self, b: &[f64], x: &mut [f64], scratch: &mut [f64], forward: bool) {
        let g = self.grid;
        let offsets = g.slot_offsets();
        let classes = if forward { [0, 1, 2] } else { [2, 1, 0] };
        for class in classes {
            let rows = |r: &usize| (PAD..g.height + PAD).contains(r) && (r - PAD) % 3 == class;
            let x_old: &[f64] = x;
            scratch
                .par_chunks_mut(g.stride)
                .enumerate()
                .filter(|(r, _)| rows(r))
                .for_each(|(r, out)| {
                    let first = r * g.stride + PAD;
                    let n = g.width;
                    let out = &mut out[PAD..PAD + n];
                    // b minus the couplings to other rows (slots 3.. reach down).
                    out.copy_from_slice(&b[first..first + n]);
                    for (plane, &off) in self.upper.iter().zip(&offsets).skip(3) {
                        let forward = plane[first..first + n]
                            .iter()
                            .zip(&x_old[first + off..first + off + n]);
                        let backward = plane[first - off..first - off + n]
                            .iter()
                            .zip(&x_old[first - off..first - off + n]);
                        for ((o, (&uf, &xf)), (&ub, &xb)) in
                            out.iter_mut().zip(forward).zip(backward)
                        {
                            *o -= f64::from(uf) * xf + f64::from(ub) * xb;
                        }
                    }
                    let (d, u1, u2) = (
                        &self.diagonal[first..first + n],
                        &self.upper[1][first - 2..first + n],
                        &self.upper[2][first - 2..first + n],
                    );
                    // Along the row: neighbours at ±1, ±2, new where visited.
                    let mut row: Vec<f64> = Vec::with_capacity(n + 4);
                    row.extend_from_slice(&x_old[first - 2..first + n + 2]);
                    let mut relax = |i: usize| {
                        let d = d[i];
                        if d > 0.0 {
                            let (j, c) = (i + 2, i + 2);
                            let sum = out[i]
                                - f64::from(u1[c]) * row[j + 1]
                                - f64::from(u2[c]) * row[j + 2]
                                - f64::from(u1[c - 1]) * row[j - 1]
                                - f64::from(u2[c - 2]) * row[j - 2];
                            row[j] = sum / d;
                        }
                    };
                    if forward {
                        (0..n).for_each(&mut relax);
                    } else {
                        (0..n).rev().for_each(&mut relax);
                    }
                    out.copy_from_slice(&row[2..n + 2]);
                });
            x.par_chunks_mut(g.stride)
                .zip(scratch.par_chunks(g.stride))
                .enumerate()
                .filter(|(r, _)| rows(r))
                .for_each(|(_, (x, s))| {
                    x[PAD..PAD + g.width].copy_from_slice(&s[PAD..PAD + g.width])
                });
        }
    }

    /// Storage index of pixel `(x, y)` when it is on the grid.
    fn pixel(&self, x: isize, y: isize) -> Option<usize> {
        let g = self.grid;
        (x >= 0 && y >= 0 && (x as usize) < g.width && (y as usize) < g.height).then(|| g.at(x, y))
    }
}

/// Unknowns per node of a coarse level, one per parity class of the finest
/// pixels (module doc); component `c` has parity `(c & 1, c >> 1)`.
const COMPONENTS: usize = 4;

/// A coarse node's neighbour `k` (0..9, row by row, 4 is the node itself).
fn neighbour(k: usize) -> (isize, isize) {
    ((k % 3) as isize - 1, (k / 3) as isize - 1)
}

/// The node itself among its neighbours.
const CENTRE: usize = 4;

/// Neighbours at or after the node in raster order: the Galerkin product
/// computes their blocks, the others are their transposes.
const UPPER: [usize; 5] = [4, 5, 6, 7, 8];

/// Pivots of a diagonal block below this fraction of their diagonal entry
/// are dropped by the smoother's block solve ([`block_inverse`]).
const BLOCK_PIVOT: f64 = 1e-5;

/// A coarse level: four unknowns per node, coupled to the 8 neighbouring
/// nodes by 4×4 blocks. A vector holds the components of a node together:
/// component `c` of the node at storage index `i` is element `4 i + c`.
pub(crate) struct Blocks {
    grid: Grid,
    /// `couplings[i][k]`: the block between node `i`'s components (rows,
    /// row by row) and those of its neighbour `k` (columns).
    couplings: Vec<[[Coefficient; 16]; 9]>,
    /// The symmetric block solve of every node's diagonal block.
    inverse: Vec<[f64; 16]>,
}

/// The level a coarse level is built from and interpolates to: the pixels
/// of the finest level, taken 2×2 at a time as the four components of a
/// node, or a coarse level.
#[derive(Clone, Copy)]
enum Fine<'a> {
    Pixels(&'a Level),
    Blocks(&'a Blocks),
}

impl Fine<'_> {
    /// Nodes along x and y.
    fn nodes(self) -> (usize, usize) {
        match self {
            Fine::Pixels(level) => (level.grid.width.div_ceil(2), level.grid.height.div_ceil(2)),
            Fine::Blocks(level) => (level.grid.width, level.grid.height),
        }
    }

    /// Storage index of component `c` of node `(x, y)`, if it is on the level.
    #[inline]
    fn index(self, x: isize, y: isize, c: usize) -> Option<usize> {
        match self {
            Fine::Pixels(level) => level.pixel(2 * x + (c & 1) as isize, 2 * y + (c >> 1) as isize),
            Fine::Blocks(level) => {
                let g = level.grid;
                (x >= 0 && y >= 0 && (x as usize) < g.width && (y as usize) < g.height)
                    .then(|| COMPONENTS * g.at(x, y) + c)
            }
        }
    }

    /// The block between node `(x, y)` and node `(x + dx, y + dy)` (`|dx|`,
    /// `|dy|` ≤ 1).
    fn block(self, x: isize, y: isize, dx: isize, dy: isize) -> [f64; 16] {
        let mut out = [0.0; 16];
        match self {
            Fine::Pixels(level) => {
                for c in 0..COMPONENTS {
                    let Some(p) = self.index(x, y, c) else {
                        continue;
                    };
                    for d in 0..COMPONENTS {
                        let ox = 2 * dx + (d & 1) as isize - (c & 1) as isize;
                        let oy = 2 * dy + (d >> 1) as isize - (c >> 1) as isize;
                        if ox.abs() <= 2 && oy.abs() <= 2 && self.index(x + dx, y + dy, d).is_some()
                        {
                            out[COMPONENTS * c + d] = level.coefficient(p, ox, oy);
                        }
                    }
                }
            }
            Fine::Blocks(level) => {
                if let Some(i) = self.index(x, y, 0) {
                    let k = ((dy + 1) * 3 + dx + 1) as usize;
                    for (o, &v) in out.iter_mut().zip(&level.couplings[i / COMPONENTS][k]) {
                        *o = f64::from(v);
                    }
                }
            }
        }
        out
    }
}

impl Blocks {
    /// The level below `fine`: `Pᵀ A P` with `P` bilinear on each component
    /// (module doc). Its blocks again couple neighbouring nodes only.
    fn below(fine: Fine) -> Blocks {
        let (width, height) = fine.nodes();
        let grid = Grid::new(width / 2 + 1, height / 2 + 1);
        // Per axis offset d (−1..=1) of the neighbour: the fine offsets
        // (a, b) of the supports of I and I + d that the fine blocks
        // couple, and the weight product.
        let pairs: [Vec<(isize, isize, f64)>; 3] = [-1isize, 0, 1].map(|d| {
            let mut list = Vec::new();
            for a in -1..=1isize {
                for b in -1..=1isize {
                    if (2 * d + b - a).abs() <= 1 {
                        list.push((a, b, weight(a) * weight(b)));
                    }
                }
            }
            list
        });
        let mut upper = vec![[[0.0 as Coefficient; 16]; UPPER.len()]; grid.len()];
        upper
            .par_chunks_mut(grid.stride)
            .enumerate()
            .filter(|(r, _)| (PAD..grid.height + PAD).contains(r))
            .for_each(|(r, row)| {
                let cy = (r - PAD) as isize;
                for cx in 0..grid.width as isize {
                    for (u, &k) in UPPER.iter().enumerate() {
                        let (dx, dy) = neighbour(k);
                        if cx + dx < 0
                            || cx + dx >= grid.width as isize
                            || cy + dy >= grid.height as isize
                        {
                            continue;
                        }
                        let mut sum = [0.0f64; 16];
                        for &(ay, by, wy) in &pairs[(dy + 1) as usize] {
                            for &(ax, bx, wx) in &pairs[(dx + 1) as usize] {
                                let block = fine.block(
                                    2 * cx + ax,
                                    2 * cy + ay,
                                    2 * dx + bx - ax,
                                    2 * dy + by - ay,
                                );
                                for (s, v) in sum.iter_mut().zip(block) {
                                    *s += wx * wy * v;
                                }
                            }
                        }
                        row[cx as usize + PAD][u] = sum.map(|v| v as Coefficient);
                    }
                }
            });
        // The lower neighbours' blocks mirror the upper ones exactly, so the
        // level is symmetric.
        let couplings: Vec<[[Coefficient; 16]; 9]> = (0..grid.len())
            .into_par_iter()
            .map(|i| {
                let mut all = [[0.0; 16]; 9];
                for (u, &k) in UPPER.iter().enumerate() {
                    all[k] = upper[i][u];
                    let j = i as isize - grid.offset(neighbour(k).0, neighbour(k).1);
                    if k != CENTRE && j >= 0 && (j as usize) < grid.len() {
                        let block = &upper[j as usize][u];
                        all[8 - k] = std::array::from_fn(|e| block[(e % 4) * 4 + e / 4]);
                    }
                }
                all
            })
            .collect();
        drop(upper);
        let inverse = couplings
            .par_iter()
            .map(|c| block_inverse(&c[CENTRE]))
            .collect();
        Blocks {
            grid,
            couplings,
            inverse,
        }
    }

    /// Elements of a vector on the level.
    fn len(&self) -> usize {
        COMPONENTS * self.grid.len()
    }

    /// `out = b − A x`, in parallel rows.
    fn residual(&self, b: &[f64], x: &[f64], out: &mut [f64]) {
        let g = self.grid;
        let offsets: [isize; 9] = std::array::from_fn(|k| g.offset(neighbour(k).0, neighbour(k).1));
        out.par_chunks_mut(COMPONENTS * g.stride)
            .enumerate()
            .filter(|(r, _)| (PAD..g.height + PAD).contains(r))
            .for_each(|(r, out)| {
                for col in PAD..PAD + g.width {
                    let i = r * g.stride + col;
                    let mut sum: [f64; 4] = std::array::from_fn(|c| b[COMPONENTS * i + c]);
                    for (block, &off) in self.couplings[i].iter().zip(&offsets) {
                        let j = COMPONENTS * (i as isize + off) as usize;
                        subtract(&mut sum, block, &x[j..j + COMPONENTS]);
                    }
                    out[COMPONENTS * col..COMPONENTS * (col + 1)].copy_from_slice(&sum);
                }
            });
    }

    /// One block Gauss–Seidel sweep on `A x = b` (`scratch`: a vector on the
    /// level): all components of a node at once. Rows of nodes are visited
    /// in two classes by parity (blocks reach one row), each row in
    /// parallel against the other class, then node by node along the row;
    /// `forward`: classes 0, 1 and left to right, otherwise the exact
    /// reverse (see [`Level::gauss_seidel`]).
    fn gauss_seidel(&self, b: &[f64], x: &mut [f64], scratch: &mut [f64], forward: bool) {
        let g = self.grid;
        let row_len = COMPONENTS * g.stride;
        let offsets: [isize; 9] = std::array::from_fn(|k| g.offset(neighbour(k).0, neighbour(k).1));
        let classes = if forward { [0, 1] } else { [1, 0] };
        for class in classes {
            let rows = |r: &usize| (PAD..g.height + PAD).contains(r) && (r - PAD) % 2 == class;
            let x_old: &[f64] = x;
            scratch
                .par_chunks_mut(row_len)
                .enumerate()
                .filter(|(r, _)| rows(r))
                .for_each(|(r, row)| {
                    row.copy_from_slice(&x_old[r * row_len..(r + 1) * row_len]);
                    let mut relax = |col: usize| {
                        let i = r * g.stride + col;
                        let mut sum: [f64; 4] = std::array::from_fn(|c| b[COMPONENTS * i + c]);
                        for (k, (block, &off)) in self.couplings[i].iter().zip(&offsets).enumerate()
                        {
                            let j = (col as isize + off) as usize;
                            if k == CENTRE {
                                continue;
                            } else if (3..6).contains(&k) {
                                // Same row: the values being relaxed.
                                subtract(
                                    &mut sum,
                                    block,
                                    &row[COMPONENTS * j..COMPONENTS * (j + 1)],
                                );
                            } else {
                                let j = COMPONENTS * (i as isize + off) as usize;
                                subtract(&mut sum, block, &x_old[j..j + COMPONENTS]);
                            }
                        }
                        let inverse = &self.inverse[i];
                        for c in 0..COMPONENTS {
                            row[COMPONENTS * col + c] = (0..COMPONENTS)
                                .map(|d| inverse[COMPONENTS * c + d] * sum[d])
                                .sum();
                        }
                    };
                    if forward {
                        (PAD..PAD + g.width).for_each(&mut relax);
                    } else {
                        (PAD..PAD + g.width).rev().for_each(&mut relax);
                    }
                });
            x.par_chunks_mut(row_len)
                .zip(scratch.par_chunks(row_len))
                .enumerate()
                .filter(|(r, _)| rows(r))
                .for_each(|(_, (x, s))| x.copy_from_slice(s));
        }
    }

    /// The dense matrix of the level's components with non-zero rows, and
    /// their storage indices.
    fn dense(&self) -> (Mat<f64>, Vec<usize>) {
        let g = self.grid;
        let active: Vec<usize> = (0..g.height as isize)
            .flat_map(|y| (0..g.width as isize).map(move |x| g.at(x, y)))
            .flat_map(|i| (0..COMPONENTS).map(move |c| COMPONENTS * i + c))
            .filter(|&e| self.couplings[e / COMPONENTS][CENTRE][5 * (e % COMPONENTS)] > 0.0)
            .collect();
        let mut position = vec![usize::MAX; self.len()];
        for (k, &e) in active.iter().enumerate() {
            position[e] = k;
        }
        let mut m = Mat::<f64>::zeros(active.len(), active.len());
        for (k, &e) in active.iter().enumerate() {
            let (i, c) = (e / COMPONENTS, e % COMPONENTS);
            for (n, block) in self.couplings[i].iter().enumerate() {
                let j = (i as isize + g.offset(neighbour(n).0, neighbour(n).1)) as usize;
                for d in 0..COMPONENTS {
                    let p = position[COMPONENTS * j + d];
                    if p != usize::MAX {
                        m[(k, p)] = f64::from(block[COMPONENTS * c + d]);
                    }
                }
            }
        }
        (m, active)
    }
}

/// `sum −= block · x` for a 4×4 block.
#[inline]
fn subtract(sum: &mut [f64; 4], block: &[Coefficient; 16], x: &[f64]) {
    for (c, s) in sum.iter_mut().enumerate() {
        *s -= (0..COMPONENTS)
            .map(|d| f64::from(block[COMPONENTS * c + d]) * x[d])
            .sum::<f64>();
    }
}

/// The smoother's solve with a diagonal block: `L⁻ᵀ D⁺ L⁻¹` from the block's
/// `L D Lᵀ`, with pivots below [`BLOCK_PIVOT`] of their diagonal entry
/// dropped (a component outside the mask has a zero row; a node on the
/// mask's edge may carry a null vector). Symmetric, as the V-cycle needs.
fn block_inverse(block: &[Coefficient; 16]) -> [f64; 16] {
    let a = |i: usize, j: usize| f64::from(block[COMPONENTS * i + j]);
    let mut l = [[0.0f64; 4]; 4];
    let mut pivot = [0.0f64; 4];
    for j in 0..COMPONENTS {
        let p = a(j, j) - (0..j).map(|k| l[j][k] * l[j][k] * pivot[k]).sum::<f64>();
        if a(j, j) <= 0.0 || p <= BLOCK_PIVOT * a(j, j) {
            continue;
        }
        pivot[j] = p;
        for i in j + 1..COMPONENTS {
            l[i][j] = (a(i, j) - (0..j).map(|k| l[i][k] * l[j][k] * pivot[k]).sum::<f64>()) / p;
        }
    }
    // L⁻¹ by forward substitution (L has a unit diagonal).
    let mut inverse_l = [[0.0f64; 4]; 4];
    for i in 0..COMPONENTS {
        let mut row = [0.0; 4];
        row[i] = 1.0;
        for (k, &lik) in l[i][..i].iter().enumerate() {
            for (r, &v) in row.iter_mut().zip(&inverse_l[k]) {
                *r -= lik * v;
            }
        }
        inverse_l[i] = row;
    }
    std::array::from_fn(|e| {
        let (i, j) = (e / COMPONENTS, e % COMPONENTS);
        (0..COMPONENTS)
            .filter(|&k| pivot[k] > 0.0)
            .map(|k| inverse_l[k][i] * inverse_l[k][j] / pivot[k])
            .sum()
    })
}

/// Bilinear weight of a fine node `a` (−1, 0, 1) from its coarse node.
fn weight(a: isize) -> f64 {
    if a == 0 { 1.0 } else { 0.5 }
}

/// `out = Pᵀ r`: every component of a coarse node gathers the same
/// component of the fine nodes around it (bilinear weights).
fn restrict(fine: Fine, r: &[f64], coarse: &Blocks, out: &mut [f64]) {
    let g = coarse.grid;
    out.par_chunks_mut(COMPONENTS * g.stride)
        .enumerate()
        .filter(|(row, _)| (PAD..g.height + PAD).contains(row))
        .for_each(|(row, out)| {
            let cy = (row - PAD) as isize;
            for cx in 0..g.width as isize {
                for c in 0..COMPONENTS {
                    let mut sum = 0.0;
                    for a in -1..=1 {
                        for b in -1..=1 {
                            if let Some(i) = fine.index(2 * cx + b, 2 * cy + a, c) {
                                sum += weight(a) * weight(b) * r[i];
                            }
                        }
                    }
                    out[COMPONENTS * (cx as usize + PAD) + c] = sum;
                }
            }
        });
}

/// Component `c` of `P x` at fine node `(x, y)` (bilinear interpolation of
/// the coarse nodes' component `c`).
#[inline]
fn interpolate(coarse: &Blocks, values: &[f64], x: isize, y: isize, c: usize) -> f64 {
    let axis = |u: isize| -> [(isize, f64); 2] {
        if u % 2 == 0 {
            [(u / 2, 1.0), (u / 2, 0.0)]
        } else {
            [(u / 2, 0.5), (u / 2 + 1, 0.5)]
        }
    };
    let mut sum = 0.0;
    for (cy, wy) in axis(y) {
        for (cx, wx) in axis(x) {
            sum += wx * wy * values[COMPONENTS * coarse.grid.at(cx, cy) + c];
        }
    }
    sum
}

/// `out += P x` on the nodes of `fine`.
fn prolong_add(coarse: &Blocks, values: &[f64], fine: Fine, out: &mut [f64]) {
    match fine {
        Fine::Pixels(level) => {
            let g = level.grid;
            out.par_chunks_mut(g.stride)
                .enumerate()
                .filter(|(row, _)| (PAD..g.height + PAD).contains(row))
                .for_each(|(row, out)| {
                    let py = (row - PAD) as isize;
                    for px in 0..g.width as isize {
                        let c = (px & 1) as usize + 2 * (py & 1) as usize;
                        out[px as usize + PAD] += interpolate(coarse, values, px / 2, py / 2, c);
                    }
                });
        }
        Fine::Blocks(level) => {
            let g = level.grid;
            out.par_chunks_mut(COMPONENTS * g.stride)
                .enumerate()
                .filter(|(row, _)| (PAD..g.height + PAD).contains(row))
                .for_each(|(row, out)| {
                    let y = (row - PAD) as isize;
                    for x in 0..g.width as isize {
                        for c in 0..COMPONENTS {
                            out[COMPONENTS * (x as usize + PAD) + c] +=
                                interpolate(coarse, values, x, y, c);
                        }
                    }
                });
        }
    }
}

/// Vectors one coarse level's cycle works in.
struct Work {
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
}

impl Work {
    fn new(level: &Blocks) -> Self {
        Work {
            b: vec![0.0; level.len()],
            x: vec![0.0; level.len()],
            r: vec![0.0; level.len()],
        }
    }
}

/// The multigrid hierarchy of one operator and its V-cycle.
pub(crate) struct Multigrid {
    /// The coarse levels, finest first (at least one).
    levels: Vec<Blocks>,
    /// Pseudo-inverse of the coarsest level's dense matrix and the storage
    /// index of each of its rows.
    coarsest: (Mat<f64>, Vec<usize>),
    /// Scratch vector on the finest level.
    scratch: Vec<f64>,
    work: Vec<Work>,
}

/// Eigenvalues below this fraction of the largest are the null space.
const PSEUDO_INVERSE_CUTOFF: f64 = 1e-10;

impl Multigrid {
    /// The hierarchy below `fine` (which stays the caller's).
    pub fn new(fine: &Level) -> Self {
        let mut levels = vec![Blocks::below(Fine::Pixels(fine))];
        loop {
            let last = levels.last().expect("one level at least");
            let g = last.grid;
            if g.width * g.height <= COARSEST || g.width.max(g.height) <= 2 {
                break;
            }
            levels.push(Blocks::below(Fine::Blocks(last)));
        }
        let (matrix, active) = levels.last().expect("one level at least").dense();
        let coarsest = (pseudo_inverse(&matrix), active);
        let work = levels.iter().map(Work::new).collect();
        Multigrid {
            levels,
            coarsest,
            scratch: vec![0.0; fine.grid.len()],
            work,
        }
    }

    /// `z = M r`, one V-cycle from zero on `fine` (the level `new` was given).
    pub fn apply(&mut self, fine: &Level, r: &[f64], z: &mut [f64]) {
        z.fill(0.0);
        for _ in 0..SWEEPS {
            fine.gauss_seidel(r, z, &mut self.scratch, true);
        }
        fine.residual(Some(r), z, &mut self.scratch);
        let (first, rest) = self.work.split_first_mut().expect("one work per level");
        restrict(
            Fine::Pixels(fine),
            &self.scratch,
            &self.levels[0],
            &mut first.b,
        );
        cycle(&self.levels, &self.coarsest, first, rest);
        prolong_add(&self.levels[0], &first.x, Fine::Pixels(fine), z);
        for _ in 0..SWEEPS {
            fine.gauss_seidel(r, z, &mut self.scratch, false);
        }
    }
}

/// One V-cycle from zero on `levels[0]` for `A x = b` in `work`; `rest` is
/// the work of the levels below.
fn cycle(levels: &[Blocks], coarsest: &(Mat<f64>, Vec<usize>), work: &mut Work, rest: &mut [Work]) {
    let Work { b, x, r } = work;
    x.fill(0.0);
    let level = &levels[0];
    let Some((child, deeper)) = rest.split_first_mut() else {
        let (inverse, active) = coarsest;
        for (k, &i) in active.iter().enumerate() {
            x[i] = active
                .iter()
                .enumerate()
                .map(|(j, &jj)| inverse[(k, j)] * b[jj])
                .sum();
        }
        return;
    };
    for _ in 0..SWEEPS {
        level.gauss_seidel(b, x, r, true);
    }
    level.residual(b, x, r);
    restrict(Fine::Blocks(level), r, &levels[1], &mut child.b);
    cycle(&levels[1..], coarsest, child, deeper);
    prolong_add(&levels[1], &child.x, Fine::Blocks(level), x);
    for _ in 0..SWEEPS {
        level.gauss_seidel(b, x, r, false);
    }
}

/// Pseudo-inverse of a symmetric positive semi-definite matrix, computed on
/// one thread (faer's default parallelism follows the thread count and
/// changes the rounding).
fn pseudo_inverse(m: &Mat<f64>) -> Mat<f64> {
    let n = m.nrows();
    let params = Default::default();
    let mut s = Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    let mut buffer = MemBuffer::new(self_adjoint_evd_scratch::<f64>(
        n,
        ComputeEigenvectors::Yes,
        Par::Seq,
        params,
    ));
    let stack = MemStack::new(&mut buffer);
    if self_adjoint_evd(
        m.as_ref(),
        s.as_mut(),
        Some(u.as_mut()),
        Par::Seq,
        stack,
        params,
    )
    .is_err()
    {
        return Mat::zeros(n, n);
    }
    let s = s.column_vector();
    let largest = (0..n).map(|i| s[i].abs()).fold(0.0, f64::max);
    let mut scaled = u.clone();
    for j in 0..n {
        let inv = if s[j] > PSEUDO_INVERSE_CUTOFF * largest {
            1.0 / s[j]
        } else {
            0.0
        };
        for i in 0..n {
            scaled[(i, j)] *= inv;
        }
    }
    let mut out = Mat::<f64>::zeros(n, n);
    matmul(
        &mut out,
        Accum::Replace,
        &scaled,
        u.transpose(),
        1.0,
        Par::Seq,
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random symmetric positive semi-definite operator on a masked grid
    /// (weighted differences between pixels up to 2 apart, zero outside
    /// the mask).
    fn level(width: usize, height: usize) -> Level {
        let grid = Grid::new(width, height);
        let inside = |x: isize, y: isize| {
            x >= 0
                && y >= 0
                && (x as usize) < width
                && (y as usize) < height
                && (x * 7 + y * 3) % 13 != 0
        };
        let mut planes = vec![vec![0.0; grid.len()]; 13];
        let mut seed = 1u64;
        for y in 0..height as isize {
            for x in 0..width as isize {
                for (s, &(dx, dy)) in SLOTS.iter().enumerate().skip(1) {
                    if !(inside(x, y) && inside(x + dx, y + dy)) {
                        continue;
                    }
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let w = (seed >> 33) as f64 / (1u64 << 31) as f64;
                    let (i, j) = (grid.at(x, y), grid.at(x + dx, y + dy));
                    planes[s][i] -= w;
                    planes[0][i] += w;
                    planes[0][j] += w;
                }
            }
        }
        Level::new(grid, planes)
    }

    #[test]
    fn the_v_cycle_is_symmetric() {
        // Conjugate gradients need a symmetric preconditioner:
        // (M a)·b = a·(M b).
        let fine = level(37, 29);
        let mut multigrid = Multigrid::new(&fine);
        let n = fine.grid.len();
        let vector = |phase: f64| -> Vec<f64> {
            let mut v = vec![0.0; n];
            for y in 0..29 {
                for x in 0..37 {
                    v[fine.grid.at(x, y)] = ((x as f64) * 0.37 + (y as f64) * phase).sin();
                }
            }
            v
        };
        let (a, b) = (vector(0.11), vector(0.53));
        let (mut ma, mut mb) = (vec![0.0; n], vec![0.0; n]);
        multigrid.apply(&fine, &a, &mut ma);
        multigrid.apply(&fine, &b, &mut mb);
        let dot = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(p, q)| p * q).sum::<f64>();
        let (left, right) = (dot(&ma, &b), dot(&a, &mb));
        assert!(
            (left - right).abs() < 1e-9 * left.abs().max(1.0),
            "{left} vs {right}"
        );
        assert!(dot(&ma, &a) > 0.0);
    }
}
