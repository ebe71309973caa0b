//! The authors' finite differences on the refined mask (spec §2,
//! "SmoothedCentral") and their Laplacian (spec §3.2). They differ from
//! `solver::operators`: the smoothed central difference along x needs only
//! the left and right neighbours and the four diagonals (not all eight
//! neighbours), and the Laplacian's weights grow where neighbours are
//! missing. `y` points up (conventions.md §1), so the row above is `+y`.

use crate::solver::domain::Domain;
use crate::solver::operators::Stencil;

/// `∂z/∂x` and `∂z/∂y` of every unknown.
#[derive(Clone, Debug)]
pub struct Gradients {
    pub dx: Vec<Stencil>,
    pub dy: Vec<Stencil>,
}

impl Gradients {
    /// The stencils of every unknown of `domain`, a refined mask's
    /// (`refine`): each pixel has a horizontal and a vertical neighbour.
    pub fn new(domain: &Domain) -> Gradients {
        let (dx, dy) = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                let (x, y) = (x as isize, y as isize);
                let diagonals = [(-1, -1), (1, -1), (-1, 1), (1, 1)]
                    .iter()
                    .all(|&(a, b)| domain.at(x + a, y + b).is_some());
                let along_x = |t: isize, s: isize| domain.at(x + s, y + t);
                // Stepping `s` along +y is stepping `−s` rows.
                let along_y = |t: isize, s: isize| domain.at(x + t, y - s);
                (
                    difference(k, diagonals, along_x),
                    difference(k, diagonals, along_y),
                )
            })
            .unzip();
        Gradients { dx, dy }
    }

    /// `(p, q) = (∂z/∂x, ∂z/∂y)` of unknown `k` at heights `z`.
    pub fn at(&self, k: usize, z: &[f64]) -> (f64, f64) {
        (self.dx[k].apply(z), self.dy[k].apply(z))
    }

    /// The stencil of `a · ∂z/∂x + b · ∂z/∂y` at unknown `k`.
    pub fn combine(&self, k: usize, a: f64, b: f64) -> Stencil {
        self.dx[k].combine(a, &self.dy[k], b)
    }
}

/// One derivative: `at(t, s)` is the unknown `s` steps along the axis and
/// `t` across it. Central differences (smoothed `[1, 4, 1]/6` across when
/// the four diagonals are inside) where both neighbours are, one-sided
/// otherwise; a refined mask always has one of them.
fn difference(
    k: usize,
    diagonals: bool,
    at: impl Fn(isize, isize) -> Option<usize>,
) -> Stencil {
    let mut s = Stencil::default();
    match (at(0, -1), at(0, 1)) {
        (Some(_), Some(_)) if diagonals => {
            for (t, w) in [(-1, 1.0), (0, 4.0), (1, 1.0)] {
                let (b, f) = (at(t, -1).expect("diagonal"), at(t, 1).expect("diagonal"));
                s.push(f, w / 12.0);
                s.push(b, -w / 12.0);
            }
        }
        (Some(back), Some(fwd)) => {
            s.push(fwd, 0.5);
            s.push(back, -0.5);
        }
        (None, Some(fwd)) => {
            s.push(fwd, 1.0);
            s.push(k, -1.0);
        }
        (Some(back), None) => {
            s.push(k, 1.0);
            s.push(back, -1.0);
        }
        (None, None) => unreachable!("a refined mask pixel has a neighbour on each axis"),
    }
    s
}

/// The authors' Laplacian at unknown `k`: centre −4 and each of the `m`
/// present 4-neighbours `4/m`. Their code writes 1.33 for `m = 3` (spec Q3),
/// a row sum of −0.01 that pulls the surface towards `z = 0`; the port uses
/// 4/3, so the cost is blind to a constant height as every other term is,
/// unless `authors_quirks` asks for their 1.33.
pub fn laplacian(domain: &Domain, k: usize, authors_quirks: bool) -> Stencil {
    let (x, y) = domain.pixel(k);
    let near: Vec<usize> = [(1, 0), (-1, 0), (0, 1), (0, -1)]
        .iter()
        .filter_map(|&(a, b)| domain.at(x as isize + a, y as isize + b))
        .collect();
    let mut s = Stencil::default();
    s.push(k, -4.0);
    for &j in &near {
        let w = match near.len() {
            3 if authors_quirks => 1.33,
            m => 4.0 / m as f64,
        };
        s.push(j, w);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::yu2017::refine::refine;
    use sfp_core::Mask;

    fn weight(domain: &Domain, s: &Stencil, x: usize, y: usize) -> f64 {
        let k = domain.at(x as isize, y as isize).unwrap();
        s.entries().find(|&(j, _)| j == k).map_or(0.0, |(_, c)| c)
    }

    #[test]
    fn hand_cases_of_each_stencil() {
        // Rows (y down): a full 3×3 block at x 0..2, with (3,1) and (3,2)
        // added right of the lower two rows.
        let mask = Mask::from_fn(5, 3, |x, y| x < 3 || (x == 3 && y > 0));
        let domain = Domain::new(&mask);
        let g = Gradients::new(&domain);
        let k = |x, y| domain.at(x, y).unwrap();
        // Centre (1,1): all diagonals, smoothed: 4/12 on the edge pair.
        let dx = &g.dx[k(1, 1)];
        assert!((weight(&domain, dx, 2, 1) - 4.0 / 12.0).abs() < 1e-15);
        assert!((weight(&domain, dx, 0, 0) + 1.0 / 12.0).abs() < 1e-15);
        // y up: the row above (row 0) is +y.
        let dy = &g.dy[k(1, 1)];
        assert!((weight(&domain, dy, 1, 0) - 4.0 / 12.0).abs() < 1e-15);
        assert!((weight(&domain, dy, 2, 2) + 1.0 / 12.0).abs() < 1e-15);
        // (2,1): left and right present, diagonals (3,0), (3,2) missing:
        // plain central difference.
        let dx = &g.dx[k(2, 1)];
        assert_eq!(weight(&domain, dx, 3, 1), 0.5);
        assert_eq!(weight(&domain, dx, 1, 1), -0.5);
        assert_eq!(dx.entries().count(), 2);
        // (3,1): only left: backward difference; (0,0): only down: y
        // backward, q = z[r] − z[r+1].
        let dx = &g.dx[k(3, 1)];
        assert_eq!((weight(&domain, dx, 3, 1), weight(&domain, dx, 2, 1)), (1.0, -1.0));
        let dy = &g.dy[k(0, 0)];
        assert_eq!((weight(&domain, dy, 0, 0), weight(&domain, dy, 0, 1)), (1.0, -1.0));
    }

    #[test]
    fn stencils_are_exact_on_planes_and_laplacian_rows_sum_to_zero() {
        let mask = refine(&Mask::from_fn(13, 11, |x, y| {
            let (dx, dy) = (x as f64 - 6.0, y as f64 - 5.0);
            dx * dx + dy * dy < 22.0 && !(x == 6 && y < 3)
        }));
        let domain = Domain::new(&mask);
        let g = Gradients::new(&domain);
        let z: Vec<f64> = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                0.7 * x as f64 - 1.3 * -(y as f64) + 2.0
            })
            .collect();
        for k in 0..domain.len() {
            let (p, q) = g.at(k, &z);
            assert!((p - 0.7).abs() < 1e-12 && (q + 1.3).abs() < 1e-12);
            let l = laplacian(&domain, k, false);
            assert!(l.entries().map(|(_, c)| c).sum::<f64>().abs() < 1e-12);
            let three = l.entries().count() == 4;
            let quirk: f64 = laplacian(&domain, k, true).entries().map(|(_, c)| c).sum();
            assert!((quirk + if three { 0.01 } else { 0.0 }).abs() < 1e-12);
        }
    }
}
