//! Normals ⇄ height with the operators every method uses.
//!
//! `normals → height`: with `n ∝ [−z_x, −z_y, 1]` (conventions.md §1), each
//! pixel gives `n_z · D_x z = −n_x` and `n_z · D_y z = −n_y`, solved by masked
//! least squares (`lsq`). The rows are multiplied through by `n_z` rather than
//! divided: a grazing normal then carries little weight instead of an
//! unbounded gradient. The zenith is first clamped to [`MAX_ZENITH_DEG`]
//! (azimuth kept): a noisy DoP above the diffuse model's maximum inverts to
//! θ = 90°, and rows weighted by `n_z ≈ 1e-17` would vanish and leave whole
//! limb clusters unconstrained (a singular system).
//!
//! Those smoothed central differences (`operators`) do not see a height that
//! alternates between neighbours (their Fourier symbol vanishes at `ω = π`,
//! `multigrid`): integrated with them alone, such a corrugation is held
//! only by the mask edge's one-sided rows, and the edge's clamped or noisy
//! normals spread it over the whole map. The heights then look like a
//! stipple in any mesh viewer (its face normals are compact differences),
//! while the normals of the heights through the same stencils hide it. So
//! every pair of horizontal and vertical neighbours with usable normals
//! also gives the compact row `z_j − z_k = (p_k + p_j) / 2` (the trapezoid
//! rule, exact for quadratic heights; `p` each pixel's slope along the
//! pair), weighted by the pair's mean `n_z` and as much as the smoothed
//! rows ([`COMPACT_WEIGHT`]). Measured as the RMS over the mask of
//! `z(x−1) − 2z(x) + z(x+1) − (z(x−2) − 2z(x) + z(x+2)) / 4` (zero to fourth
//! order on smooth heights): SMSfP's heights of the 512² analytic sphere
//! 0.64 → 0.073 px (their error against the sphere inside 0.9 of its radius
//! 0.098 → 0.019 px), Atkinson's 0.91 → 0.097 px, SMSfP's of the
//! 1224×1024 fruit capture 0.51 → 0.034 px; with the compact rows at 0.1
//! and 0.3 of the smoothed ones' weight the sphere kept 0.32 and 0.16 px.
//! The rows fit in the 13-slot layout (`slots`): the solvers are unchanged.
//!
//! `height → normals`: `n = normalise([−D_x z, −D_y z, 1])` with the same
//! stencils. A pixel without a neighbour along an axis gets 0 for that
//! derivative (documented fallback; a one-pixel object faces the camera).

use crate::solver::domain::Domain;
use crate::solver::lsq::{NormalEquations, Solver};
use crate::solver::operators::{Operators, Stencil};
use crate::solver::ordering::Ordering;
use rayon::prelude::*;
use sfp_core::{Error, Image, Mask, NormalMap, Result};

/// Integration systems with at least this many unknowns are solved by
/// conjugate gradients with multigrid (`lsq::Solver::with_iterative_min`),
/// in memory linear in the mask's bounding box instead of a factor of
/// ≈ 2 KB per unknown. Their iterations depend on the normals and on the
/// mask: 6 for the 1024² analytic sphere's true normals (1.07 s against
/// 2.9 s factorised, `--bench solver`), 19 for Atkinson's normals of it (the
/// method 2.67 s and 0.36 GB against 3.21 s and 1.37 GB factorised), 40 for
/// Atkinson's of the 1224×1024 fruit capture, whose mask has slivers and
/// necks (5.32 s against 4.90 s; 24 iterations with the mask eroded by 3
/// pixels), 34 for Atkinson's of the 5 MP capture (18.0 s, 1.27 GB peak;
/// factorised 5.47 GB). So the factorisation stays below a million
/// unknowns (≤ 2 GB), where on real captures it is as fast or faster.
pub const ITERATIVE_MIN: usize = 1_000_000;

/// Weight of the compact rows between neighbours relative to the smoothed
/// central ones (module doc): equal, neither discretisation preferred.
const COMPACT_WEIGHT: f64 = 1.0;

/// Largest zenith angle (degrees) a normal is integrated with. At 89° a row
/// keeps weight `cos 89° ≈ 0.017` and asks for a slope of `tan 89° ≈ 57`.
pub const MAX_ZENITH_DEG: f64 = 89.0;

/// `n` normalised, with its zenith clamped to [`MAX_ZENITH_DEG`] (azimuth
/// kept); `None` when it is not finite, zero or faces away (`n_z < 0`).
fn integrable(n: [f64; 3]) -> Option<[f64; 3]> {
    let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if !norm.is_finite() || norm == 0.0 || n[2] < 0.0 {
        return None;
    }
    let [nx, ny, nz] = n.map(|v| v / norm);
    let (sin_max, cos_max) = MAX_ZENITH_DEG.to_radians().sin_cos();
    if nz >= cos_max {
        return Some([nx, ny, nz]);
    }
    let planar = (nx * nx + ny * ny).sqrt();
    Some([nx / planar * sin_max, ny / planar * sin_max, cos_max])
}

/// Least-squares height (pixel units, zero mean per connected component, NaN
/// outside `mask`) whose gradients best match `normals`. Pixels without a
/// usable normal (zero, non-finite or facing away) carry no rows; grazing
/// normals are clamped (see the module doc).
pub fn height_from_normals(normals: &NormalMap, mask: &Mask) -> Result<Image<f32>> {
    height_from_normals_with(normals, mask, &mut solver())
}

/// Relative residual at which the integration's conjugate gradients stop.
/// The heights are the end of the road (no normal is read back from them),
/// so they need the accuracy of a surface, not the solver default's, which
/// SMSfP's refinement needs for the normals it compounds. SMSfP's heights
/// of the 1224×1024 fruit capture against those at 1e-6: at 1e-4 they move
/// by 5e-4 px on average (the object spans 1,050 px of height; largest
/// 0.023 px) and their normals by 5e-4° (largest 0.11°), in 28 iterations
/// instead of 36 (1e-5: 31; 1e-3: 25, normals 0.002°, largest 0.44°); the
/// 1024² analytic sphere's in 4 instead of 6.
pub const TOLERANCE: f64 = 1e-4;

/// The integration's solver (see [`ITERATIVE_MIN`], [`TOLERANCE`]).
fn solver() -> Solver {
    Solver::new(Ordering::default())
        .with_iterative_min(ITERATIVE_MIN)
        .with_tolerance(TOLERANCE)
}

/// A solver with the symbolic factorisation for `mask` computed: a method
/// builds it on the second core while it computes its normals, then passes it
/// to [`height_from_normals_with`].
pub fn solver_for(mask: &Mask) -> Solver {
    let mut solver = solver();
    solver.prepare(&Domain::new(mask));
    solver
}

/// [`height_from_normals`] with a given (possibly prepared) solver.
pub fn height_from_normals_with(
    normals: &NormalMap,
    mask: &Mask,
    solver: &mut Solver,
) -> Result<Image<f32>> {
    let domain = Domain::new(mask);
    let eq = equations(normals, &domain)?;
    let z = solver.solve(&eq)?.z.swap_remove(0);
    Ok(heights(&domain, &z))
}

/// [`height_from_normals`] by conjugate gradients with multigrid whatever
/// the size, from `guess` (a height per unknown of `mask`'s domain) or
/// from zero (`Solver::solve_near`).
pub fn height_near(normals: &NormalMap, mask: &Mask, guess: Option<&[f64]>) -> Result<Image<f32>> {
    let domain = Domain::new(mask);
    let eq = equations(normals, &domain)?;
    let guess = guess.map(|g| vec![g.to_vec()]);
    let z = solver().solve_near(&eq, guess.as_deref())?.z.swap_remove(0);
    Ok(heights(&domain, &z))
}

/// `z` as an image, NaN outside the domain.
fn heights(domain: &Domain, z: &[f64]) -> Image<f32> {
    let z: Vec<f32> = z.iter().map(|&v| v as f32).collect();
    domain.scatter(&z, f32::NAN)
}

/// The integration's rows (module doc) of `normals` over `domain`.
pub fn equations<'a>(normals: &NormalMap, domain: &'a Domain) -> Result<NormalEquations<'a>> {
    if normals.size() != domain.size() {
        return Err(Error::invalid("normal map and mask differ in size"));
    }
    let ops = Operators::new(domain);
    let mut eq = NormalEquations::new(domain);
    let usable: Vec<Option<[f64; 3]>> = (0..domain.len())
        .map(|k| {
            let (x, y) = domain.pixel(k);
            integrable(normals.get(x, y).map(f64::from))
        })
        .collect();
    for (k, n) in usable.iter().enumerate() {
        let Some(n) = *n else {
            continue;
        };
        let [nx, ny, nz] = n;
        if let Some(dx) = ops.dx(k) {
            eq.add(&dx, -nx / nz, nz);
        }
        if let Some(dy) = ops.dy(k) {
            eq.add(&dy, -ny / nz, nz);
        }
        // The compact rows to the right and upper neighbours (module doc).
        let (x, y) = domain.pixel(k);
        let (x, y) = (x as isize, y as isize);
        for (neighbour, axis) in [(domain.at(x + 1, y), 0), (domain.at(x, y - 1), 1)] {
            if let Some(j) = neighbour
                && let Some(m) = usable[j]
            {
                let mut row = Stencil::default();
                row.push(k, -1.0);
                row.push(j, 1.0);
                let slope = -(n[axis] / n[2] + m[axis] / m[2]) / 2.0;
                eq.add(&row, slope, COMPACT_WEIGHT * (n[2] + m[2]) / 2.0);
            }
        }
    }
    Ok(eq)
}

/// Normals of `height` over `mask` by the finite differences of `operators`;
/// `[0, 0, 0]` outside the mask.
pub fn normals_from_height(height: &Image<f32>, mask: &Mask) -> NormalMap {
    let domain = Domain::new(mask);
    let z: Vec<f64> = domain.gather(height).into_iter().map(f64::from).collect();
    let normals = normals_of(&domain, &z);
    domain.scatter(&normals, [0.0; 3])
}

/// Unit normals at every unknown from heights `z` (see the module doc).
pub fn normals_of(domain: &Domain, z: &[f64]) -> Vec<[f32; 3]> {
    let ops = Operators::new(domain);
    (0..domain.len())
        .into_par_iter()
        .map(|k| {
            let gx = ops.dx(k).map_or(0.0, |s| s.apply(z));
            let gy = ops.dy(k).map_or(0.0, |s| s.apply(z));
            let norm = (gx * gx + gy * gy + 1.0).sqrt();
            [
                (-gx / norm) as f32,
                (-gy / norm) as f32,
                (1.0 / norm) as f32,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest deviation between `got` and `exact` after removing each one's
    /// mean over the mask (heights are defined up to a constant).
    fn max_error(got: &Image<f32>, exact: &Image<f64>, mask: &Mask) -> f64 {
        let inside: Vec<(f64, f64)> = (0..mask.len())
            .filter(|&i| mask.data()[i])
            .map(|i| (f64::from(got.data()[i]), exact.data()[i]))
            .collect();
        let n = inside.len() as f64;
        let mg = inside.iter().map(|p| p.0).sum::<f64>() / n;
        let me = inside.iter().map(|p| p.1).sum::<f64>() / n;
        inside
            .iter()
            .map(|p| ((p.0 - mg) - (p.1 - me)).abs())
            .fold(0.0, f64::max)
    }

    /// Exact normals of `z(X, Y)` with gradient `grad(X, Y)` in camera coordinates.
    fn normals_of_field(
        w: usize,
        h: usize,
        mask: &Mask,
        grad: impl Fn(f64, f64) -> (f64, f64),
    ) -> NormalMap {
        NormalMap::from_fn(w, h, |x, y| {
            if !*mask.get(x, y) {
                return [0.0; 3];
            }
            let (gx, gy) = grad(x as f64 + 0.5, -(y as f64 + 0.5));
            let n = (gx * gx + gy * gy + 1.0).sqrt();
            [(-gx / n) as f32, (-gy / n) as f32, (1.0 / n) as f32]
        })
    }

    #[test]
    fn plane_is_recovered_exactly() {
        let (w, h) = (40, 30);
        let mask = Mask::from_fn(w, h, |x, y| (x + 2 * y) % 17 != 0 || x < 3);
        let (a, b) = (0.4, -0.25);
        let normals = normals_of_field(w, h, &mask, |_, _| (a, b));
        let z = height_from_normals(&normals, &mask).unwrap();
        let exact = Image::from_fn(w, h, |x, y| a * (x as f64 + 0.5) - b * (y as f64 + 0.5));
        let e = max_error(&z, &exact, &mask);
        assert!(e < 1e-4, "plane max height error {e}");
        // Back to normals through the same stencils, wherever both
        // derivatives exist (elsewhere the documented fallback applies).
        let back = normals_from_height(&z, &mask);
        let domain = Domain::new(&mask);
        let ops = Operators::new(&domain);
        let mut checked = 0;
        for k in 0..domain.len() {
            if ops.dx(k).is_none() || ops.dy(k).is_none() {
                continue;
            }
            let (x, y) = domain.pixel(k);
            let (got, want) = (back.get(x, y), normals.get(x, y));
            let d: f32 = (0..3).map(|c| (got[c] - want[c]).abs()).sum();
            assert!(d < 1e-4, "normal at {x},{y}: {got:?} vs {want:?}");
            checked += 1;
        }
        assert!(checked > domain.len() * 9 / 10);
    }

    #[test]
    fn paraboloid_and_sphere_cap() {
        let (w, h) = (64, 64);
        let (cx, cy) = (32.0, -32.0);
        let mask = Mask::from_fn(w, h, |x, y| {
            let (dx, dy) = (x as f64 + 0.5 - cx, -(y as f64 + 0.5) - cy);
            dx * dx + dy * dy < 28.0 * 28.0
        });
        // Paraboloid z = −0.01 r².
        let normals = normals_of_field(w, h, &mask, |x, y| (-0.02 * (x - cx), -0.02 * (y - cy)));
        let z = height_from_normals(&normals, &mask).unwrap();
        let exact = Image::from_fn(w, h, |x, y| {
            let (dx, dy) = (x as f64 + 0.5 - cx, -(y as f64 + 0.5) - cy);
            -0.01 * (dx * dx + dy * dy)
        });
        let e = max_error(&z, &exact, &mask);
        assert!(e < 0.05, "paraboloid max height error {e} px (range ~8 px)");
        // Sphere cap of radius 40 over a disc of radius 28 (rim slope ~45°).
        let r = 40.0f64;
        let normals = normals_of_field(w, h, &mask, |x, y| {
            let (dx, dy) = (x - cx, y - cy);
            let s = (r * r - dx * dx - dy * dy).sqrt();
            (-dx / s, -dy / s)
        });
        let z = height_from_normals(&normals, &mask).unwrap();
        let exact = Image::from_fn(w, h, |x, y| {
            let (dx, dy) = (x as f64 + 0.5 - cx, -(y as f64 + 0.5) - cy);
            (r * r - dx * dx - dy * dy).sqrt()
        });
        let e = max_error(&z, &exact, &mask);
        assert!(e < 0.1, "sphere cap max height error {e} px (range ~11 px)");
        // Conjugate gradients, from zero and from the exact heights, give
        // the factorisation's heights.
        let domain = Domain::new(&mask);
        let start: Vec<f64> = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                *exact.get(x, y)
            })
            .collect();
        for guess in [None, Some(&start[..])] {
            let near = height_near(&normals, &mask, guess).unwrap();
            let e = max_error(&near, &z.map(|&v| f64::from(v)), &mask);
            assert!(e < 1e-3, "iterative against factorised: {e} px");
        }
    }

    #[test]
    fn heights_are_not_corrugated() {
        // A whole hemisphere, so that the limb's normals are clamped, with
        // a deterministic ±0.01 perturbation of the normals as a method's
        // would have.
        let (w, h, r) = (96, 96, 44.0f64);
        let mask = Mask::from_fn(w, h, |x, y| {
            (x as f64 + 0.5 - 48.0).hypot(y as f64 + 0.5 - 48.0) < r
        });
        let exact = NormalMap::from_fn(w, h, |x, y| {
            let (dx, dy) = (x as f64 + 0.5 - 48.0, 48.0 - (y as f64 + 0.5));
            let nz = (r * r - dx * dx - dy * dy).max(0.0).sqrt();
            let wobble = (((x * 7 + y * 13) % 5) as f64 - 2.0) * 0.005;
            [
                (dx / r + wobble) as f32,
                (dy / r - wobble) as f32,
                (nz / r) as f32,
            ]
        });
        let z = height_from_normals(&exact, &mask).unwrap();
        // Second difference minus the second difference over twice the
        // step: zero to fourth order on a smooth height, `−4a` on a
        // corrugation `±a` (module doc), inside 0.8 of the radius.
        let (mut sum, mut count) = (0.0, 0);
        for y in 0..h {
            for x in 2..w - 2 {
                let (dx, dy) = (x as f64 + 0.5 - 48.0, y as f64 + 0.5 - 48.0);
                if dx.hypot(dy) > 0.8 * r {
                    continue;
                }
                let v: Vec<f64> = (x - 2..=x + 2).map(|i| f64::from(*z.get(i, y))).collect();
                let d = (v[1] - 2.0 * v[2] + v[3]) - (v[0] - 2.0 * v[2] + v[4]) / 4.0;
                sum += d * d;
                count += 1;
            }
        }
        let rms = (sum / count as f64).sqrt();
        // 0.45 px with the smoothed rows alone, 2e-4 px with the compact ones.
        assert!(rms < 0.02, "corrugation {rms} px");
    }

    #[test]
    fn components_and_holes_are_integrated_separately() {
        let (w, h) = (50, 20);
        // Two squares, one with a hole; different tilts.
        let mask = Mask::from_fn(w, h, |x, y| {
            let left = (2..20).contains(&x)
                && (2..18).contains(&y)
                && !((8..12).contains(&x) && (8..12).contains(&y));
            let right = (25..45).contains(&x) && (3..15).contains(&y);
            left || right
        });
        let grad = |x: f64, _y: f64| if x < 22.0 { (0.3, 0.1) } else { (-0.2, 0.5) };
        let normals = normals_of_field(w, h, &mask, grad);
        let z = height_from_normals(&normals, &mask).unwrap();
        for (range, (a, b)) in [(0..22, (0.3, 0.1)), (22..50, (-0.2, 0.5))] {
            let part = Mask::from_fn(w, h, |x, y| *mask.get(x, y) && range.contains(&x));
            let exact = Image::from_fn(w, h, |x, y| a * (x as f64 + 0.5) - b * (y as f64 + 0.5));
            assert!(max_error(&z, &exact, &part) < 1e-4);
            // Each component has zero mean on its own.
            let mean: f64 = (0..part.len())
                .filter(|&i| part.data()[i])
                .map(|i| f64::from(z.data()[i]))
                .sum::<f64>();
            assert!(mean.abs() < 1e-2);
        }
        assert!(z.get(0, 0).is_nan() && z.get(10, 10).is_nan());
    }
}
