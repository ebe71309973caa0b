//! Geometric multigrid on the bounding box of a masked grid: the
//! preconditioner of the conjugate-gradient solver (`conjugate_gradient`).
//!
//! Every level is a rectangle of pixels stored with a zero border of
//! [`PAD`] pixels, holding the symmetric operator in the 13-slot upper layout
//! of `slots` as 13 planes (one per slot, structure of arrays, so a product
//! streams through memory in straight runs the compiler vectorises). Pixels
//! outside the mask have zero rows: they never move.
//!
//! Coarse level `l + 1` has a node on every other pixel of level `l`
//! (vertex-centred), the interpolation `P` is bilinear (weights 1, ½, ¼;
//! they sum to 1 at every fine pixel, so constants, the operator's null
//! space on each connected piece, are interpolated exactly) and the coarse
//! operator is Galerkin's `Pᵀ A P`. Its stencil again couples nodes at
//! most 2 apart, so every level keeps the 13-slot layout.
//!
//! One V-cycle: forward Gauss–Seidel sweeps, the coarse correction, then
//! as many backward sweeps, so the cycle is a symmetric operator, as
//! conjugate gradients needs (the order is in [`Level::gauss_seidel`]). The coarsest level (at most
//! [`COARSEST`] nodes) is solved with the pseudo-inverse of its dense
//! matrix: it stays singular (one constant per piece of the mask).

use super::slots::{SLOTS, slot};
use faer::{Mat, Side};
use rayon::prelude::*;

/// Zero border around every level, the reach of the operator's couplings.
pub(crate) const PAD: usize = 2;

/// Coarsening stops once a level has at most this many pixels.
const COARSEST: usize = 256;

/// Gauss–Seidel sweeps before and after the coarse correction (1, 2 and 4
/// sweeps cost about the same per digit on the 512² sphere's system: 58, 40
/// and 30 iterations to 1e-6).
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
pub(crate) type Coefficient = f32;

/// One level: the operator on a grid.
pub(crate) struct Level {
    pub grid: Grid,
    /// `upper[s][i]`: coupling of pixel `i` with the pixel at slot `s`, in
    /// single precision (half the memory traffic; the products accumulate
    /// in double precision).
    upper: Vec<Vec<Coefficient>>,
}

impl Level {
    /// The level of `upper` (13 planes on `grid`).
    pub fn new(grid: Grid, upper: Vec<Vec<Coefficient>>) -> Self {
        debug_assert!(upper.len() == 13 && upper.iter().all(|p| p.len() == grid.len()));
        Level { grid, upper }
    }

    /// Coefficient between storage index `p` and the pixel `(dx, dy)` from it.
    #[inline]
    fn coefficient(&self, p: usize, dx: isize, dy: isize) -> f64 {
        f64::from(if dy > 0 || (dy == 0 && dx >= 0) {
            self.upper[slot(dx, dy)][p]
        } else {
            let q = (p as isize + self.grid.offset(dx, dy)) as usize;
            self.upper[slot(-dx, -dy)][q]
        })
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
                let diagonal = &self.upper[0][start..start + n];
                for ((o, &d), &v) in out.iter_mut().zip(diagonal).zip(&x[start..start + n]) {
                    *o = f64::from(d) * v;
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
                        &self.upper[0][first..first + n],
                        &self.upper[1][first - 2..first + n],
                        &self.upper[2][first - 2..first + n],
                    );
                    // Along the row: neighbours at ±1, ±2, new where visited.
                    let mut row: Vec<f64> = Vec::with_capacity(n + 4);
                    row.extend_from_slice(&x_old[first - 2..first + n + 2]);
                    let mut relax = |i: usize| {
                        let d = f64::from(d[i]);
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

    /// The next coarser level, `Pᵀ A P` on every other pixel (module doc).
    fn coarsen(&self) -> Level {
        let fine = self.grid;
        let grid = Grid::new(fine.width / 2 + 1, fine.height / 2 + 1);
        // Per slot axis offset d (−2..=2): the fine offsets (a, b) of the
        // supports of I and I + d whose pixels the operator couples, and
        // the weight product.
        let pairs: Vec<Vec<(isize, isize, f64)>> = (-2..=2isize)
            .map(|d| {
                let mut list = Vec::new();
                for a in -1..=1isize {
                    for b in -1..=1isize {
                        if (2 * d + b - a).abs() <= 2 {
                            list.push((a, b, weight(a) * weight(b)));
                        }
                    }
                }
                list
            })
            .collect();
        let mut rows = vec![[0.0 as Coefficient; 13]; grid.len()];
        rows.par_chunks_mut(grid.stride)
            .enumerate()
            .filter(|(r, _)| (PAD..grid.height + PAD).contains(r))
            .for_each(|(r, row)| {
                let cy = (r - PAD) as isize;
                for cx in 0..grid.width as isize {
                    let node = &mut row[cx as usize + PAD];
                    for (s, &(dx, dy)) in SLOTS.iter().enumerate() {
                        let (jx, jy) = (cx + dx, cy + dy);
                        if jx < 0 || jx >= grid.width as isize || jy >= grid.height as isize {
                            continue;
                        }
                        let mut sum = 0.0;
                        for &(ay, by, wy) in &pairs[(dy + 2) as usize] {
                            for &(ax, bx, wx) in &pairs[(dx + 2) as usize] {
                                let p = fine.at(2 * cx + ax, 2 * cy + ay);
                                let c = self.coefficient(p, 2 * dx + bx - ax, 2 * dy + by - ay);
                                sum += wx * wy * c;
                            }
                        }
                        node[s] = sum as Coefficient;
                    }
                }
            });
        let upper = (0..13)
            .map(|s| rows.iter().map(|r| r[s]).collect())
            .collect();
        Level::new(grid, upper)
    }

    /// The dense matrix of the level's pixels with non-zero rows, and their
    /// storage indices.
    fn dense(&self) -> (Mat<f64>, Vec<usize>) {
        let g = self.grid;
        let active: Vec<usize> = (0..g.height as isize)
            .flat_map(|y| (0..g.width as isize).map(move |x| g.at(x, y)))
            .filter(|&i| self.upper[0][i] > 0.0)
            .collect();
        let mut position = vec![usize::MAX; g.len()];
        for (k, &i) in active.iter().enumerate() {
            position[i] = k;
        }
        let offsets = g.slot_offsets();
        let mut m = Mat::<f64>::zeros(active.len(), active.len());
        for (k, &i) in active.iter().enumerate() {
            for (s, &off) in offsets.iter().enumerate() {
                let j = position[i + off];
                if j != usize::MAX {
                    m[(k, j)] = f64::from(self.upper[s][i]);
                    m[(j, k)] = f64::from(self.upper[s][i]);
                }
            }
        }
        (m, active)
    }
}

/// Bilinear weight of a fine pixel `a` (−1, 0, 1) from its coarse node.
fn weight(a: isize) -> f64 {
    if a == 0 { 1.0 } else { 0.5 }
}

/// `coarse = Pᵀ fine` (the bilinear interpolation's transpose).
fn restrict(fine: Grid, r: &[f64], coarse: Grid, out: &mut [f64]) {
    out.par_chunks_mut(coarse.stride)
        .enumerate()
        .filter(|(row, _)| (PAD..coarse.height + PAD).contains(row))
        .for_each(|(row, out)| {
            let cy = (row - PAD) as isize;
            for cx in 0..coarse.width as isize {
                let mut sum = 0.0;
                for a in -1..=1 {
                    for b in -1..=1 {
                        sum += weight(a) * weight(b) * r[fine.at(2 * cx + b, 2 * cy + a)];
                    }
                }
                out[cx as usize + PAD] = sum;
            }
        });
}

/// `fine += P coarse` on the pixels of `fine` (bilinear interpolation).
fn prolong_add(coarse: Grid, x: &[f64], fine: Grid, out: &mut [f64]) {
    out.par_chunks_mut(fine.stride)
        .enumerate()
        .filter(|(row, _)| (PAD..fine.height + PAD).contains(row))
        .for_each(|(row, out)| {
            let y = (row - PAD) as isize;
            let ys: &[(isize, f64)] = if y % 2 == 0 {
                &[(y / 2, 1.0)]
            } else {
                &[(y / 2, 0.5), (y / 2 + 1, 0.5)]
            };
            for xf in 0..fine.width as isize {
                let xs: &[(isize, f64)] = if xf % 2 == 0 {
                    &[(xf / 2, 1.0)]
                } else {
                    &[(xf / 2, 0.5), (xf / 2 + 1, 0.5)]
                };
                let mut sum = 0.0;
                for &(cy, wy) in ys {
                    for &(cx, wx) in xs {
                        sum += wx * wy * x[coarse.at(cx, cy)];
                    }
                }
                out[xf as usize + PAD] += sum;
            }
        });
}

/// Vectors one level's cycle works in.
struct Work {
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
}

impl Work {
    fn new(grid: Grid) -> Self {
        Work {
            b: vec![0.0; grid.len()],
            x: vec![0.0; grid.len()],
            r: vec![0.0; grid.len()],
        }
    }
}

/// The multigrid hierarchy of one operator and its V-cycle.
pub(crate) struct Multigrid {
    levels: Vec<Level>,
    /// Pseudo-inverse of the coarsest level's dense matrix and the storage
    /// index of each of its rows.
    coarsest: (Mat<f64>, Vec<usize>),
    work: Vec<Work>,
}

/// Eigenvalues below this fraction of the largest are the null space.
const PSEUDO_INVERSE_CUTOFF: f64 = 1e-10;

impl Multigrid {
    /// The hierarchy below `fine` (which stays the caller's).
    pub fn new(fine: &Level) -> Self {
        let mut levels: Vec<Level> = Vec::new();
        loop {
            let last = levels.last().unwrap_or(fine);
            if last.grid.width * last.grid.height <= COARSEST
                || last.grid.width.max(last.grid.height) <= 2
            {
                break;
            }
            levels.push(last.coarsen());
        }
        let (matrix, active) = levels.last().unwrap_or(fine).dense();
        let coarsest = (pseudo_inverse(&matrix), active);
        let mut work = vec![Work::new(fine.grid)];
        work.extend(levels.iter().map(|l| Work::new(l.grid)));
        Multigrid {
            levels,
            coarsest,
            work,
        }
    }

    /// `z = M r`, one V-cycle from zero on `fine` (the level `new` was given).
    pub fn apply(&mut self, fine: &Level, r: &[f64], z: &mut [f64]) {
        let mut levels: Vec<&Level> = vec![fine];
        levels.extend(self.levels.iter());
        let (first, rest) = self.work.split_first_mut().expect("one work per level");
        cycle(&levels, &self.coarsest, r, z, &mut first.r, rest);
    }
}

/// One V-cycle from zero on `levels[0]` for `A x = b`; `r` is the level's
/// scratch, `rest` the work of the levels below.
fn cycle(
    levels: &[&Level],
    coarsest: &(Mat<f64>, Vec<usize>),
    b: &[f64],
    x: &mut [f64],
    r: &mut [f64],
    rest: &mut [Work],
) {
    x.fill(0.0);
    let level = levels[0];
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
    level.residual(Some(b), x, r);
    let coarse = levels[1].grid;
    let Work {
        b: cb,
        x: cx,
        r: cr,
    } = child;
    restrict(level.grid, r, coarse, cb);
    cycle(&levels[1..], coarsest, cb, cx, cr, deeper);
    prolong_add(coarse, cx, level.grid, x);
    for _ in 0..SWEEPS {
        level.gauss_seidel(b, x, r, false);
    }
}

/// Pseudo-inverse of a symmetric positive semi-definite matrix.
fn pseudo_inverse(m: &Mat<f64>) -> Mat<f64> {
    let n = m.nrows();
    if n == 0 {
        return Mat::zeros(0, 0);
    }
    let Ok(eigen) = m.self_adjoint_eigen(Side::Lower) else {
        return Mat::zeros(n, n);
    };
    let (u, s) = (eigen.U(), eigen.S().column_vector());
    let largest = (0..n).map(|i| s[i].abs()).fold(0.0, f64::max);
    let mut scaled = u.to_owned();
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
    scaled * u.transpose()
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
                    let w = ((seed >> 33) as f64 / (1u64 << 31) as f64) as Coefficient;
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
