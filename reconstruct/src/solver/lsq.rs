//! Sparse linear least squares `min ‖C z − d‖²` over the heights of a
//! [`Domain`], solved through the normal equations `CᵀC z = Cᵀd` with faer's
//! sparse Cholesky factorisation.
//!
//! Every row a method adds is a [`Stencil`] (at most a 3×3 neighbourhood), so
//! `CᵀC` couples only pixels at most 2 apart in x and y: it is accumulated
//! directly, without forming `C`, in 13 slots per unknown (the diagonal and
//! the 12 neighbours that come later in raster order) — far less memory and
//! time than building `C` and multiplying.
//!
//! All constraints the methods use act on `∇z`, so a constant added to a
//! connected piece of the surface does not change the residual and `CᵀC` is
//! singular. The solver splits the unknowns into the 8-connected components
//! of the domain (the components of the regularised `CᵀC`, see below), pins
//! the first pixel of each (removes it from the system), solves, and shifts
//! each component to zero mean. An isolated pixel has height 0.
//!
//! Pinning removes the constant, but noisy data can still leave unknowns
//! (nearly) unconstrained — a cluster of pixels without rows, or with rows of
//! vanishing weight — and the factorisation would then fail. The solver
//! therefore always adds a tiny membrane term
//! `ε Σ (z_i − z_j)²` over 8-neighbour pixel pairs, with `ε` = [`MEMBRANE`]
//! × the mean diagonal of `CᵀC`. Pinned, it makes every component positive
//! definite; unconstrained pixels take the smooth (harmonic) interpolation of
//! their neighbours; elsewhere it perturbs heights by a relative ~ε
//! (both operators are Laplacian-like, so no mode is amplified).
//!
//! Several right-hand sides may share one matrix (rows whose coefficients
//! differ only in sign give the same `CᵀC`, as the two members of the
//! convex/concave light ambiguity do): they cost one factorisation and one
//! triangular solve each.
//!
//! The symbolic factorisation (fill-reducing ordering and elimination
//! structure) depends only on the sparsity pattern, which is taken from the
//! domain (every slot inside the same component, zero or not): [`Solver`]
//! keeps it, reuses it when the same domain is solved again, and can compute
//! it ahead ([`Solver::prepare`]) on another core while a method is still
//! computing its rows.
//!
//! A system whose Cholesky factor would not fit in the available memory is
//! solved instead by conjugate gradients preconditioned with multigrid
//! (`conjugate_gradient`, `multigrid`, `pieces`), in memory linear in the
//! domain's bounding box; they agree with the factorisation to a relative
//! residual of `conjugate_gradient::TOLERANCE` (or the one a caller sets,
//! `Solver::with_tolerance`).
//!
//! A large component is solved as two halves and the separator between them
//! (`substructure`), so its two factorisations run on two cores: 512²
//! integration system (166k unknowns) 0.57 s instead of 0.89 s, 1024²
//! 3.2 s instead of 6.3 s. From [`MIXED_MIN`] unknowns on, the factor is
//! computed in single precision and the answer refined to double (`mixed`).

use super::conjugate_gradient::{BoxSystem, TOLERANCE};
use super::mixed::MIXED_MIN;
use super::multigrid::Multigrid;
use super::pieces;
use super::plan::{FLOORED_MIN, Plan, Precision};
use super::slots::{Entries, SLOTS, slot, slot_pixel};
use crate::solver::cholesky::{SparseCholesky, check_memory};
use crate::solver::domain::Domain;
use crate::solver::operators::Stencil;
use crate::solver::ordering::{Ordering, fill_reducing};
use crate::solver::substructure::Substructure;
use sfp_core::regions::Regions;
use sfp_core::{Error, Result};
use std::time::Instant;

/// Membrane weight relative to the mean diagonal of `CᵀC` (see the module
/// doc): small enough to leave well-posed solutions unchanged to ~1e-9,
/// large enough for a Cholesky pivot far above f64 rounding.
pub const MEMBRANE: f64 = 1e-9;

/// The normal equations `CᵀC z = Cᵀd` of a least-squares problem, accumulated
/// row by row.
#[derive(Clone, Debug)]
pub struct NormalEquations<'a> {
    domain: &'a Domain,
    /// `CᵀC[k][slot]`: coupling of unknown `k` with the unknown at `SLOTS[slot]`.
    upper: Vec<[f64; 13]>,
    /// `Cᵀd`, one vector per right-hand side.
    rhs: Vec<Vec<f64>>,
    rows: usize,
}

impl<'a> NormalEquations<'a> {
    /// Equations with one right-hand side.
    pub fn new(domain: &'a Domain) -> Self {
        Self::with_right_hand_sides(domain, 1)
    }

    /// Equations with `count` right-hand sides sharing the matrix.
    pub fn with_right_hand_sides(domain: &'a Domain, count: usize) -> Self {
        NormalEquations {
            domain,
            upper: vec![[0.0; 13]; domain.len()],
            rhs: vec![vec![0.0; domain.len()]; count.max(1)],
            rows: 0,
        }
    }

    pub fn domain(&self) -> &'a Domain {
        self.domain
    }

    /// Number of rows added.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Adds the equation `weight · (row · z) = weight · value` to every
    /// right-hand side.
    pub fn add(&mut self, row: &Stencil, value: f64, weight: f64) {
        self.accumulate(row, weight, |_| value);
    }

    /// Adds `weight · (row · z) = weight · values[i]` to right-hand side `i`.
    pub fn add_each(&mut self, row: &Stencil, values: &[f64], weight: f64) {
        assert_eq!(
            values.len(),
            self.rhs.len(),
            "one value per right-hand side"
        );
        self.accumulate(row, weight, |i| values[i]);
    }

    fn accumulate(&mut self, row: &Stencil, weight: f64, value: impl Fn(usize) -> f64) {
        let w2 = weight * weight;
        for (a, ca) in row.entries() {
            for (i, rhs) in self.rhs.iter_mut().enumerate() {
                rhs[a] += w2 * ca * value(i);
            }
            let (xa, ya) = self.domain.pixel(a);
            for (b, cb) in row.entries() {
                if b < a {
                    continue;
                }
                let (xb, yb) = self.domain.pixel(b);
                let s = slot(xb as isize - xa as isize, yb as isize - ya as isize);
                self.upper[a][s] += w2 * ca * cb;
            }
        }
        self.rows += 1;
    }

    /// `ε` of the membrane term (module doc).
    fn membrane_weight(&self) -> f64 {
        let n = self.upper.len();
        let mean = self.upper.iter().map(|u| u[0]).sum::<f64>() / n.max(1) as f64;
        MEMBRANE * if mean > 0.0 { mean } else { 1.0 }
    }

    /// `CᵀC` plus the membrane term of the module doc.
    fn with_membrane(&self) -> Entries<'_> {
        Entries::new(&self.upper, self.domain).with_membrane(self.membrane_weight())
    }
}

/// The 8-connected components of the domain (`regions`): the component of
/// every unknown and each component's unknowns in raster order. A row
/// couples only pixels of one stencil (inside a 3×3 neighbourhood of a
/// domain pixel) and the membrane couples all 8-neighbours, so these are the
/// components of the regularised `CᵀC`, whatever the rows: the sparsity
/// pattern, and so the symbolic factorisation, depends on the domain alone
/// (see [`Solver::prepare`]).
fn components(domain: &Domain) -> (Vec<u32>, Vec<Vec<usize>>) {
    let regions = Regions::components(&domain.mask());
    let label = (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            *regions.labels.get(x, y)
        })
        .collect();
    let members = regions
        .list
        .iter()
        .map(|r| {
            r.pixels
                .iter()
                .map(|&i| {
                    domain
                        .unknown(i)
                        .expect("component pixels are in the domain")
                })
                .collect()
        })
        .collect();
    (label, members)
}

/// The solution and how it was obtained.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Heights per unknown, zero mean per component, one vector per
    /// right-hand side.
    pub z: Vec<Vec<f64>>,
    /// Connected components solved (including single pixels).
    pub components: usize,
    /// Components solved as two halves on two cores (`substructure`).
    pub split: usize,
    /// Seconds spent on fill-reducing ordering and symbolic factorisation.
    pub seconds_symbolic: f64,
    /// Seconds spent on numeric factorisation and triangular solves.
    pub seconds_numeric: f64,
    /// Components whose symbolic factorisation came from the cache.
    pub symbolic_reused: usize,
    /// Conjugate-gradient iterations (summed over right-hand sides; 0 when
    /// the direct solver ran).
    pub iterations: usize,
}

/// A plan and the pixels of the system it belongs to.
struct Cached {
    /// Image width and height, then the raster index of every unknown.
    key: Vec<usize>,
    plan: Plan,
    /// Where the next system on these unknowns starts (the last one's
    /// precision): a method's next system on the same unknowns (SMSfP's
    /// refinement) differs from the last by a few parts in a thousand, and
    /// each failed attempt at 5 MP cost 3.2–3.5 s per half million unknowns.
    precision: Precision,
}

/// Sparse Cholesky solver that remembers symbolic factorisations.
pub struct Solver {
    ordering: Ordering,
    /// Components with at least this many unknowns are split in two
    /// (nested dissection only).
    split_min: usize,
    /// Domains with at least this many unknowns are solved iteratively
    /// (otherwise only those whose factor would not fit in memory).
    iterative_min: usize,
    /// Systems with at least this many unknowns are factorised in single
    /// precision and refined (`mixed`).
    mixed_min: usize,
    /// Systems with at least this many unknowns try [`Precision::Floored`].
    floored_min: usize,
    /// Conjugate gradients stop at this residual relative to the
    /// right-hand side's.
    tolerance: f64,
    cache: Vec<Cached>,
}

/// Smallest component split in two halves. The split pays off early:
/// sphere integration systems, best of 7 on 2 cores, whole vs split: 2.6k
/// unknowns 2.8 vs 2.4 ms, 10k 18.5 vs 15.9 ms, 23k 47 vs 33 ms; below a
/// couple of thousand unknowns neither takes measurable time.
const SPLIT_MIN: usize = 2_000;

/// Symbolic factorisations kept; a method solves a handful of patterns.
const CACHE_SIZE: usize = 16;

impl Solver {
    pub fn new(ordering: Ordering) -> Self {
        Solver {
            ordering,
            split_min: SPLIT_MIN,
            iterative_min: usize::MAX,
            mixed_min: MIXED_MIN,
            floored_min: FLOORED_MIN,
            tolerance: TOLERANCE,
            cache: Vec::new(),
        }
    }

    /// Splits components from `split_min` unknowns on (tests exercise the
    /// split on small problems).
    pub fn with_split_min(mut self, split_min: usize) -> Self {
        self.split_min = split_min;
        self
    }

    /// Factorises systems from `mixed_min` unknowns on in single precision
    /// (tests exercise it on small problems).
    pub fn with_mixed_min(mut self, mixed_min: usize) -> Self {
        self.mixed_min = mixed_min;
        self
    }

    /// Tries the floored single-precision factor from `floored_min`
    /// unknowns on (tests exercise it on small problems).
    pub fn with_floored_min(mut self, floored_min: usize) -> Self {
        self.floored_min = floored_min;
        self
    }

    /// Stops conjugate gradients at `tolerance` (default
    /// `conjugate_gradient::TOLERANCE`).
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// Solves domains from `iterative_min` unknowns on with conjugate
    /// gradients (default `usize::MAX`: only when a Cholesky factor would
    /// not fit in memory).
    pub fn with_iterative_min(mut self, iterative_min: usize) -> Self {
        self.iterative_min = iterative_min;
        self
    }

    /// Computes and caches the symbolic factorisations `solve` will need for
    /// any equations on `domain` (they depend on the domain alone), so this
    /// can run while the equations are being assembled. A factorisation
    /// that cannot be planned is left to `solve` (conjugate gradients).
    pub fn prepare(&mut self, domain: &Domain) {
        if domain.len() >= self.iterative_min {
            // The iterative solver's hierarchy depends on the values.
            return;
        }
        for list in components(domain).1.iter().filter(|l| l.len() > 1) {
            if self.plan(domain, &list[1..]).is_err() {
                break;
            }
        }
    }

    /// Solves the least-squares problem behind `eq` (see the module doc for
    /// the gauge: one pixel pinned per component, then zero mean).
    pub fn solve(&mut self, eq: &NormalEquations) -> Result<Solution> {
        let n = eq.domain.len();
        let members = checked_components(eq)?;
        if n >= self.iterative_min
            && let Some(solution) = iterative(eq, &members, None, self.tolerance)?
        {
            return Ok(solution);
        }
        let matrix = eq.with_membrane();
        let mut z = vec![vec![0.0; n]; eq.rhs.len()];
        let mut solution = Solution {
            z: Vec::new(),
            components: members.len(),
            split: 0,
            seconds_symbolic: 0.0,
            seconds_numeric: 0.0,
            symbolic_reused: 0,
            iterations: 0,
        };
        // The fewest unknowns of a component whose plain single-precision
        // factor failed: a component at least as large skips that attempt.
        // The components of one system share its kinds of rows, and the
        // weakest modes they leave weaken as the domain grows (the 5 MP
        // fruit capture: Smith's 0.97 M component fails in 1.0 s, its 1.54 M
        // one in 1.5 s). Components are solved in turn, so the choice does
        // not depend on thread scheduling.
        let mut single_fails_from = usize::MAX;
        for list in members.iter().filter(|l| l.len() > 1) {
            // The first member is pinned at height 0.
            let system = &list[1..];
            let start = Instant::now();
            let planned = self.plan(eq.domain, system);
            solution.seconds_symbolic += start.elapsed().as_secs_f64();
            let factorisable = planned.and_then(|reused| {
                let plan = &self.cache.last().expect("planned above").plan;
                check_memory(plan.factor_bytes(), list.len()).map(|()| reused)
            });
            match factorisable {
                Ok(reused) => solution.symbolic_reused += usize::from(reused),
                // Beyond the factorisation's 32-bit indices (`cholesky`) or
                // the memory available: conjugate gradients, in memory
                // linear in the domain.
                Err(refused) => {
                    drop(z);
                    return iterative(eq, &members, None, self.tolerance)?.ok_or(refused);
                }
            }
            let cached = self.cache.last_mut().expect("planned above");
            let plan = &cached.plan;
            let start = Instant::now();
            // The single-precision attempts left for these unknowns.
            let (mixed, floored) = (
                system.len() >= self.mixed_min,
                system.len() >= self.floored_min,
            );
            let singles: Vec<Precision> = [Precision::Single, Precision::Floored]
                .into_iter()
                .filter(|&p| mixed && p >= cached.precision)
                .filter(|&p| match p {
                    Precision::Single => system.len() < single_fails_from,
                    Precision::Floored => floored,
                    Precision::Double => false,
                })
                .collect();
            cached.precision = plan.solve(eq.domain, matrix, system, &singles, &eq.rhs, &mut z)?;
            if singles.contains(&Precision::Single) && cached.precision != Precision::Single {
                single_fails_from = single_fails_from.min(system.len());
            }
            solution.split += usize::from(matches!(plan, Plan::Split(_)));
            solution.seconds_numeric += start.elapsed().as_secs_f64();
            for z in &mut z {
                center(z, list)?;
            }
        }
        solution.z = z;
        Ok(solution)
    }

    /// [`Solver::solve`] by conjugate gradients whatever the size, started
    /// from `guess` (one height per unknown for each right-hand side) or
    /// from zero; factorises when they do not converge. For systems whose
    /// iterations are known to be few (SMSfP's integration), or whose
    /// solution is known to lie near.
    pub fn solve_near(
        &mut self,
        eq: &NormalEquations,
        guess: Option<&[Vec<f64>]>,
    ) -> Result<Solution> {
        if guess.is_some_and(|g| {
            g.len() != eq.rhs.len() || g.iter().any(|g| g.len() != eq.domain.len())
        }) {
            return Err(Error::invalid(
                "a starting guess needs one height per unknown for each right-hand side",
            ));
        }
        let members = checked_components(eq)?;
        match iterative(eq, &members, guess, self.tolerance)? {
            Some(solution) => Ok(solution),
            None => self.solve(eq),
        }
    }

    /// Puts the plan for the unknowns `system` last in the cache, computing
    /// it unless it is there already (then returns `true`).
    fn plan(&mut self, domain: &Domain, system: &[usize]) -> Result<bool> {
        let (width, height) = domain.size();
        let key: Vec<usize> = [width, height]
            .into_iter()
            .chain(system.iter().map(|&k| {
                let (x, y) = domain.pixel(k);
                y * width + x
            }))
            .collect();
        if let Some(i) = self.cache.iter().position(|c| c.key == key) {
            let hit = self.cache.remove(i);
            self.cache.push(hit);
            return Ok(true);
        }
        let split = if self.ordering == Ordering::NestedDissection && system.len() >= self.split_min
        {
            Substructure::new(domain, system)?
        } else {
            None
        };
        let plan = match split {
            Some(split) => Plan::Split(Box::new(split)),
            None => Plan::Whole(Box::new(SparseCholesky::new(
                domain,
                system.to_vec(),
                fill_reducing(self.ordering, domain, system),
                false,
            )?)),
        };
        if self.cache.len() == CACHE_SIZE {
            self.cache.remove(0);
        }
        self.cache.push(Cached {
            key,
            plan,
            precision: Precision::Single,
        });
        Ok(false)
    }
}

/// The connected components of `eq`'s domain; fails when a row couples
/// two of them.
fn checked_components(eq: &NormalEquations) -> Result<Vec<Vec<usize>>> {
    let (label, members) = components(eq.domain);
    let crossing = (0..eq.domain.len()).any(|k| {
        (1..SLOTS.len()).any(|s| {
            eq.upper[k][s] != 0.0
                && slot_pixel(eq.domain, k, s).is_some_and(|j| label[j] != label[k])
        })
    });
    if crossing {
        return Err(Error::invalid(
            "a row couples pixels that are not 8-connected inside the mask",
        ));
    }
    Ok(members)
}

/// Checks one component's heights `list` of `z` and gives them zero mean
/// (the constant of integration is not observable).
fn center(z: &mut [f64], list: &[usize]) -> Result<()> {
    if list.iter().any(|&k| !z[k].is_finite()) {
        return Err(Error::invalid(
            "least-squares solution is not finite (ill-conditioned constraints)",
        ));
    }
    let mean = list.iter().map(|&k| z[k]).sum::<f64>() / list.len() as f64;
    for &k in list {
        z[k] -= mean;
    }
    Ok(())
}

/// The solution of `eq` by conjugate gradients (connected components
/// `members`), or `None` when they do not converge (the caller then
/// factorises).
fn iterative(
    eq: &NormalEquations,
    members: &[Vec<usize>],
    guess: Option<&[Vec<f64>]>,
    tolerance: f64,
) -> Result<Option<Solution>> {
    let start = Instant::now();
    let (piece, pieces) = pieces::pieces(eq.domain, &eq.upper);
    let system = BoxSystem::new(eq.domain, &eq.upper);
    let mut multigrid = Multigrid::new(system.level());
    let seconds_symbolic = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let mut z = Vec::with_capacity(eq.rhs.len());
    let mut iterations = 0;
    for (i, rhs) in eq.rhs.iter().enumerate() {
        let from = guess.map(|g| g[i].as_slice());
        let (solved, taken) = system.solve(&mut multigrid, rhs, from, &piece, pieces, tolerance);
        iterations += taken;
        let Some(mut solved) = solved else {
            return Ok(None);
        };
        let offsets = pieces::offsets(eq.domain, &piece, pieces, &solved);
        for (v, &p) in solved.iter_mut().zip(&piece) {
            *v += offsets[p as usize];
        }
        for list in members {
            center(&mut solved, list)?;
        }
        z.push(solved);
    }
    Ok(Some(Solution {
        z,
        components: members.len(),
        split: 0,
        seconds_symbolic,
        seconds_numeric: start.elapsed().as_secs_f64(),
        symbolic_reused: 0,
        iterations,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::operators::Operators;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;
    use sfp_core::Mask;

    mod precision;

    /// Normal equations of `rows` with two right-hand sides, `d` and
    /// `0.5 − d`.
    fn two_right_hand_sides<'a>(
        domain: &'a Domain,
        rows: &[(Stencil, f64, f64)],
    ) -> NormalEquations<'a> {
        let mut eq = NormalEquations::with_right_hand_sides(domain, 2);
        for (s, d, w) in rows {
            eq.add_each(s, &[*d, 0.5 - d], *w);
        }
        eq
    }

    /// Every right-hand side's solution in `b` equals `a`'s to 1e-9 of its
    /// largest height.
    fn assert_same_solutions(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
        for (a, b) in a.iter().zip(b) {
            let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = a
                .iter()
                .zip(b)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                scale > 0.1 && diff < 1e-9 * scale,
                "{what} differs by {diff} (scale {scale})"
            );
        }
    }

    /// Random gradient rows on a `w × h` image's disc of radius `r` (with
    /// scattered one-pixel holes when `holes`).
    fn disc_problem(
        rng: &mut Pcg64,
        w: usize,
        h: usize,
        r: f64,
        holes: bool,
    ) -> (Domain, Vec<(Stencil, f64, f64)>) {
        let disc = Mask::from_fn(w, h, |x, y| {
            let (dx, dy) = (x as f64 - w as f64 / 2.0, y as f64 - h as f64 / 2.0);
            dx * dx + dy * dy < r * r && !(holes && (x * 13 + y * 7) % 37 == 0)
        });
        let disc = Domain::new(&disc);
        let ops = Operators::new(&disc);
        let mut rows = Vec::new();
        for k in 0..disc.len() {
            if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
                rows.push((dx, rng.random_range(-1.0..1.0), rng.random_range(0.1..2.0)));
                rows.push((dy, rng.random_range(-1.0..1.0), rng.random_range(0.1..2.0)));
            }
        }
        (disc, rows)
    }

    /// Random gradient rows on a mask with two components and a hole.
    fn random_problem(rng: &mut Pcg64) -> (Domain, Vec<(Stencil, f64, f64)>) {
        let mask = Mask::from_fn(30, 24, |x, y| {
            let blob = (x as f64 - 10.0).powi(2) + (y as f64 - 12.0).powi(2) < 64.0
                && !(x == 10 && (10..14).contains(&y));
            blob || ((20..28).contains(&x) && (3..20).contains(&y))
        });
        let domain = Domain::new(&mask);
        let ops = Operators::new(&domain);
        let mut rows = Vec::new();
        for k in 0..domain.len() {
            let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
                rows.push((dx.combine(a, &dy, b), rng.random_range(-1.0..1.0), 1.0));
                rows.push((dx, rng.random_range(-1.0..1.0), rng.random_range(0.1..2.0)));
            }
            if let Some(l) = ops.laplacian(k) {
                rows.push((l, 0.0, 0.3));
            }
        }
        (domain, rows)
    }

    /// Half-gradient of the regularised objective, `Cᵀ(Cz − d) + ε L z`
    /// (membrane over 8-neighbour pairs, `ε` from the mean diagonal of
    /// `CᵀC`), computed from the rows and the pixel grid.
    fn objective_gradient(domain: &Domain, rows: &[(Stencil, f64, f64)], z: &[f64]) -> Vec<f64> {
        let mut grad = vec![0.0; domain.len()];
        let mut diagonal = 0.0;
        for (s, d, w) in rows {
            let r = w * w * (s.apply(z) - d);
            for (k, c) in s.entries() {
                grad[k] += c * r;
                diagonal += w * w * c * c;
            }
        }
        let epsilon = MEMBRANE * diagonal / domain.len() as f64;
        for (k, g) in grad.iter_mut().enumerate() {
            let (x, y) = domain.pixel(k);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(j) = domain.at(x as isize + dx, y as isize + dy)
                        && j != k
                    {
                        *g += epsilon * (z[k] - z[j]);
                    }
                }
            }
        }
        grad
    }

    #[test]
    fn unconstrained_cluster_is_interpolated() {
        // A plane z = 0.5 x on a 12×12 square whose central 6×6 block
        // carries no rows (as pixels without a usable normal): its inner 4×4
        // appears in no row at all, so least squares alone leaves it free
        // (it used to come back as separate components at height 0). The
        // membrane fills the block from its rim (a plane is harmonic:
        // exactly).
        let mask = Mask::new(12, 12, true);
        let domain = Domain::new(&mask);
        let ops = Operators::new(&domain);
        let inside = |k: usize| {
            let (x, y) = domain.pixel(k);
            (3..9).contains(&x) && (3..9).contains(&y)
        };
        let mut eq = NormalEquations::new(&domain);
        for k in (0..domain.len()).filter(|&k| !inside(k)) {
            eq.add(&ops.dx(k).unwrap(), 0.5, 1.0);
            eq.add(&ops.dy(k).unwrap(), 0.0, 1.0);
        }
        // Factorised, and iteratively (the block's pixels are pieces of
        // their own, placed by the membrane: `pieces`).
        for iterative_min in [usize::MAX, 0] {
            let sol = Solver::new(Ordering::default())
                .with_iterative_min(iterative_min)
                .solve(&eq)
                .unwrap();
            assert_eq!(sol.components, 1);
            assert_eq!(sol.iterations > 0, iterative_min == 0);
            let z = &sol.z[0];
            for (k, &got) in z.iter().enumerate() {
                let (x, _) = domain.pixel(k);
                let want = 0.5 * (x as f64 - 5.5);
                assert!((got - want).abs() < 1e-5, "pixel {k}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn solution_satisfies_the_normal_equations() {
        let mut rng = Pcg64::seed_from_u64(7);
        let (domain, rows) = random_problem(&mut rng);
        let mut eq = NormalEquations::new(&domain);
        for (s, d, w) in &rows {
            eq.add(s, *d, *w);
        }
        let mut results = Vec::new();
        for ordering in [Ordering::Amd, Ordering::NestedDissection] {
            let mut sol = Solver::new(ordering).solve(&eq).unwrap();
            assert_eq!(sol.components, 2);
            let grad = objective_gradient(&domain, &rows, &sol.z[0]);
            let worst = grad.iter().fold(0.0f64, |m, g| m.max(g.abs()));
            assert!(worst < 1e-9, "{ordering:?}: optimality residual {worst}");
            results.push(sol.z.swap_remove(0));
        }
        let diff = results[0]
            .iter()
            .zip(&results[1])
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-9);
    }

    #[test]
    fn iterative_normals_agree_with_the_factorisation_on_an_analytic_view() {
        // The shared height-from-polarization system of an analytic sphere
        // (both light candidates): conjugate gradients with multigrid must
        // give the factorisation's normals within 0.01° MAE.
        use crate::light::Lighting;
        use crate::prior::convexity_prior;
        use crate::solver::integrate::normals_of;
        use crate::system::{PixelData, System};
        use crate::test_support::{LIGHT, analytic};
        use sfp_core::analytic::Shape;
        use sfp_core::metrics::angular_error_deg;
        let (input, _) = analytic(Shape::Sphere, 112, 1.5);
        let domain = Domain::new(&input.mask);
        let (theta, _) = input.zenith(1.5);
        let data = PixelData::gather(&domain, &input, &theta, None).unwrap();
        let prior = convexity_prior(&input.mask, 5.0);
        let system = System {
            domain: &domain,
            data: &data,
            prior: &prior,
            lambda: 0.1,
            relative: None,
        };
        let lighting = Lighting {
            ambient: 0.0,
            vector: LIGHT.map(|v| v * 0.8),
        };
        let mut eq = NormalEquations::with_right_hand_sides(&domain, 2);
        system.add_base_rows(&mut eq);
        system.add_shading_rows(&mut eq, &lighting, 2);
        let direct = Solver::new(Ordering::default()).solve(&eq).unwrap();
        let iterative = Solver::new(Ordering::default())
            .with_iterative_min(0)
            .solve(&eq)
            .unwrap();
        assert!(
            iterative.iterations > 0,
            "conjugate gradients did not converge"
        );
        for (a, b) in direct.z.iter().zip(&iterative.z) {
            let (a, b) = (normals_of(&domain, a), normals_of(&domain, b));
            let mae = a
                .iter()
                .zip(&b)
                .filter_map(|(p, q)| angular_error_deg(*p, *q))
                .sum::<f64>()
                / a.len() as f64;
            assert!(mae < 0.01, "normals differ by {mae}° MAE");
        }
    }

    #[test]
    fn iterative_solution_satisfies_the_normal_equations() {
        let mut rng = Pcg64::seed_from_u64(7);
        let (domain, rows) = random_problem(&mut rng);
        let eq = equations(&domain, &rows);
        let direct = Solver::new(Ordering::default()).solve(&eq).unwrap();
        let iterative = Solver::new(Ordering::default())
            .with_iterative_min(0)
            .solve(&eq)
            .unwrap();
        assert!(iterative.iterations > 0 && direct.iterations == 0);
        assert_near(&direct.z[0], &iterative.z[0]);
    }

    /// The normal equations of `rows` on `domain`.
    fn equations<'a>(domain: &'a Domain, rows: &[(Stencil, f64, f64)]) -> NormalEquations<'a> {
        let mut eq = NormalEquations::new(domain);
        for (s, d, w) in rows {
            eq.add(s, *d, *w);
        }
        eq
    }

    /// Asserts that heights `z` are `reference` to 1e-4 of its largest.
    fn assert_near(reference: &[f64], z: &[f64]) {
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = reference
            .iter()
            .zip(z)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(scale > 0.1 && diff < 1e-4 * scale, "{diff} (scale {scale})");
    }

    #[test]
    fn a_starting_guess_changes_the_iterations_not_the_solution() {
        let mut rng = Pcg64::seed_from_u64(11);
        let (domain, rows) = random_problem(&mut rng);
        let eq = equations(&domain, &rows);
        let direct = Solver::new(Ordering::default()).solve(&eq).unwrap();
        let mut solver = Solver::new(Ordering::default());
        let cold = solver.solve_near(&eq, None).unwrap();
        // A guess off the solution by a smooth bump and by noise.
        let guess: Vec<f64> = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                direct.z[0][k]
                    + 0.3 * (x as f64 * 0.2).sin()
                    + 0.05 * rng.random_range(-1.0..1.0)
                    + 0.01 * y as f64
            })
            .collect();
        let warm = solver
            .solve_near(&eq, Some(std::slice::from_ref(&guess)))
            .unwrap();
        let exact = solver.solve_near(&eq, Some(&direct.z)).unwrap();
        assert!(
            cold.iterations > 0 && warm.iterations > 0,
            "{cold:?} {warm:?}"
        );
        assert_eq!(exact.iterations, 0);
        for solution in [&cold, &warm, &exact] {
            assert_near(&direct.z[0], &solution.z[0]);
        }
        assert!(solver.solve_near(&eq, Some(&[vec![0.0; 3]][..])).is_err());
    }

    #[test]
    fn split_components_give_the_whole_solution() {
        // Small split threshold so both components of the random problem,
        // and a larger disc with holes, are solved as two halves and a
        // separator; the answer must be the single factorisation's.
        let mut rng = Pcg64::seed_from_u64(11);
        let (small, small_rows) = random_problem(&mut rng);
        let (disc, disc_rows) = disc_problem(&mut rng, 110, 90, 42.0, true);
        for (domain, rows) in [(&small, &small_rows), (&disc, &disc_rows)] {
            let eq = two_right_hand_sides(domain, rows);
            let whole = Solver::new(Ordering::NestedDissection)
                .with_split_min(usize::MAX)
                .solve(&eq)
                .unwrap();
            let split = Solver::new(Ordering::NestedDissection)
                .with_split_min(50)
                .solve(&eq)
                .unwrap();
            assert_eq!(whole.split, 0);
            assert!(split.split >= 1, "no component was split");
            assert_same_solutions(&whole.z, &split.z, "split");
        }
    }

    #[test]
    fn symbolic_factorisation_is_reused_for_the_same_pattern() {
        let mut rng = Pcg64::seed_from_u64(8);
        let (domain, rows) = random_problem(&mut rng);
        let mut solver = Solver::new(Ordering::NestedDissection);
        for (pass, scale) in [(0, 1.0), (1, 2.0)] {
            let mut eq = NormalEquations::new(&domain);
            for (s, d, w) in &rows {
                eq.add(s, d * scale, *w);
            }
            let sol = solver.solve(&eq).unwrap();
            assert_eq!(sol.symbolic_reused, if pass == 0 { 0 } else { 2 });
        }
    }

    #[test]
    fn right_hand_sides_share_the_matrix() {
        let mut rng = Pcg64::seed_from_u64(9);
        let (domain, rows) = random_problem(&mut rng);
        let mut joint = NormalEquations::with_right_hand_sides(&domain, 2);
        let mut separate = [NormalEquations::new(&domain), NormalEquations::new(&domain)];
        for (s, d, w) in &rows {
            joint.add_each(s, &[*d, -2.0 * d], *w);
            separate[0].add(s, *d, *w);
            separate[1].add(s, -2.0 * d, *w);
        }
        let mut solver = Solver::new(Ordering::default());
        let both = solver.solve(&joint).unwrap();
        for (i, eq) in separate.iter().enumerate() {
            let one = solver.solve(eq).unwrap();
            let diff = both.z[i]
                .iter()
                .zip(&one.z[0])
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(diff < 1e-9, "right-hand side {i}: {diff}");
        }
    }
}
