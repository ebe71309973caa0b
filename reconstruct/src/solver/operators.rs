//! Masked finite-difference operators: the discrete `z_x`, `z_y` and
//! Laplacian at a pixel as sparse rows over the unknown heights.
//!
//! Derivatives are in the camera frame of conventions.md §1: `x` grows with
//! the column, `y` grows **upwards**, i.e. against the row index, so every
//! difference along rows carries a minus sign. Pixel spacing is 1.
//!
//! Discretisation (the one Smith et al. and the SMSfP paper use, §4.4):
//! - all 8 neighbours inside the mask: the smoothed central difference, a
//!   central difference averaged across the other axis with weights
//!   `[1, 4, 1] / 6`, i.e. 4/12 on the edge neighbours and 1/12 on corners;
//! - otherwise, per axis: the central difference when both neighbours along
//!   that axis are inside, a one-sided (forward or backward) difference when
//!   one is, and no derivative when neither is.
//!
//! Every stencil is exact for linear height fields (tested below).

use crate::solver::domain::Domain;

/// At most 9 entries: a 3×3 neighbourhood.
const CAPACITY: usize = 9;

/// A sparse linear form `Σ c_k z_k` over unknown heights, touching only a
/// 3×3 neighbourhood. Duplicate unknowns are merged.
#[derive(Clone, Copy, Debug)]
pub struct Stencil {
    index: [u32; CAPACITY],
    coeff: [f64; CAPACITY],
    len: usize,
}

impl Default for Stencil {
    fn default() -> Self {
        Stencil {
            index: [0; CAPACITY],
            coeff: [0.0; CAPACITY],
            len: 0,
        }
    }
}

impl Stencil {
    /// Adds `c · z_k`.
    pub fn push(&mut self, k: usize, c: f64) {
        let k = k as u32;
        if let Some(i) = self.index[..self.len].iter().position(|&j| j == k) {
            self.coeff[i] += c;
        } else {
            assert!(
                self.len < CAPACITY,
                "stencil wider than a 3×3 neighbourhood"
            );
            self.index[self.len] = k;
            self.coeff[self.len] = c;
            self.len += 1;
        }
    }

    /// `a · self + b · other`.
    pub fn combine(&self, a: f64, other: &Stencil, b: f64) -> Stencil {
        let mut out = Stencil::default();
        for (k, c) in self.entries() {
            out.push(k, a * c);
        }
        for (k, c) in other.entries() {
            out.push(k, b * c);
        }
        out
    }

    /// `a · self`.
    pub fn scaled(&self, a: f64) -> Stencil {
        let mut out = *self;
        out.coeff[..out.len].iter_mut().for_each(|c| *c *= a);
        out
    }

    /// `(unknown, coefficient)` pairs.
    pub fn entries(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.index[..self.len]
            .iter()
            .zip(&self.coeff[..self.len])
            .map(|(&k, &c)| (k as usize, c))
    }

    /// Value of the form at heights `z`.
    pub fn apply(&self, z: &[f64]) -> f64 {
        self.entries().map(|(k, c)| c * z[k]).sum()
    }
}

/// Gradient and Laplacian stencils over a [`Domain`].
#[derive(Clone, Copy, Debug)]
pub struct Operators<'a> {
    domain: &'a Domain,
}

/// Smoothing weights across the differencing axis (offsets −1, 0, +1).
const SMOOTH: [f64; 3] = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0];

impl<'a> Operators<'a> {
    pub fn new(domain: &'a Domain) -> Self {
        Operators { domain }
    }

    pub fn domain(&self) -> &'a Domain {
        self.domain
    }

    /// `∂z/∂x` at unknown `k` (towards image right), `None` when the pixel
    /// has no horizontal neighbour in the mask.
    pub fn dx(&self, k: usize) -> Option<Stencil> {
        let (x, y) = self.signed_pixel(k);
        let at = |dx: isize, dy: isize| self.domain.at(x + dx, y + dy);
        // Derivative along +column of the pixels in row offset `r`.
        self.difference(k, |r, s| at(s, r))
    }

    /// `∂z/∂y` at unknown `k` with `y` pointing **up** (towards row 0),
    /// `None` when the pixel has no vertical neighbour in the mask.
    pub fn dy(&self, k: usize) -> Option<Stencil> {
        let (x, y) = self.signed_pixel(k);
        // Stepping `s` along camera +y is stepping `−s` rows.
        self.difference(k, |c, s| self.domain.at(x + c, y - s))
    }

    /// 5-point Laplacian at `k` when all 4 edge neighbours are inside.
    pub fn laplacian(&self, k: usize) -> Option<Stencil> {
        let (x, y) = self.signed_pixel(k);
        let mut s = Stencil::default();
        s.push(k, -4.0);
        for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            s.push(self.domain.at(x + dx, y + dy)?, 1.0);
        }
        Some(s)
    }

    /// Whether all 8 neighbours of `k` are inside the mask.
    pub fn interior(&self, k: usize) -> bool {
        let (x, y) = self.signed_pixel(k);
        (-1..=1).all(|dy| (-1..=1).all(|dx| self.domain.at(x + dx, y + dy).is_some()))
    }

    /// A derivative along one axis. `at(t, s)` is the unknown at offset `s`
    /// along the differencing axis and `t` across it.
    fn difference(&self, k: usize, at: impl Fn(isize, isize) -> Option<usize>) -> Option<Stencil> {
        let mut s = Stencil::default();
        if self.interior(k) {
            for (t, w) in (-1..=1).zip(SMOOTH) {
                s.push(at(t, 1)?, 0.5 * w);
                s.push(at(t, -1)?, -0.5 * w);
            }
            return Some(s);
        }
        match (at(0, -1), at(0, 1)) {
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
            (None, None) => return None,
        }
        Some(s)
    }

    fn signed_pixel(&self, k: usize) -> (isize, isize) {
        let (x, y) = self.domain.pixel(k);
        (x as isize, y as isize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::Mask;

    /// Camera-frame coordinates of pixel centres: `Y` grows upwards.
    fn camera_xy(domain: &Domain, k: usize) -> (f64, f64) {
        let (x, y) = domain.pixel(k);
        (x as f64 + 0.5, -(y as f64 + 0.5))
    }

    fn ragged_mask() -> Mask {
        // A disc with a notch and a one-pixel-wide spur: every stencil kind occurs.
        Mask::from_fn(12, 10, |x, y| {
            let (dx, dy) = (x as f64 - 5.0, y as f64 - 5.0);
            (dx * dx + dy * dy < 16.0 && !(x == 5 && y < 4)) || (y == 5 && x >= 9)
        })
    }

    #[test]
    fn stencils_are_exact_on_planes_with_y_up() {
        let mask = ragged_mask();
        let domain = Domain::new(&mask);
        let ops = Operators::new(&domain);
        let (a, b) = (0.7, -1.3);
        let z: Vec<f64> = (0..domain.len())
            .map(|k| {
                let (x, y) = camera_xy(&domain, k);
                a * x + b * y + 2.0
            })
            .collect();
        let (mut nx, mut ny) = (0, 0);
        for k in 0..domain.len() {
            if let Some(s) = ops.dx(k) {
                assert!((s.apply(&z) - a).abs() < 1e-12);
                nx += 1;
            }
            if let Some(s) = ops.dy(k) {
                assert!(
                    (s.apply(&z) - b).abs() < 1e-12,
                    "dy at {:?}",
                    domain.pixel(k)
                );
                ny += 1;
            }
            if let Some(s) = ops.laplacian(k) {
                assert!(s.apply(&z).abs() < 1e-12);
            }
        }
        // The spur (row 5, x ≥ 9) has no vertical neighbours.
        assert!(nx == domain.len() && ny < domain.len());
    }

    #[test]
    fn smoothed_stencil_weights() {
        let mask = Mask::new(3, 3, true);
        let domain = Domain::new(&mask);
        let ops = Operators::new(&domain);
        let centre = domain.at(1, 1).unwrap();
        let dx = ops.dx(centre).unwrap();
        let weight = |s: &Stencil, x, y| {
            let k = domain.at(x, y).unwrap();
            s.entries().find(|&(j, _)| j == k).map_or(0.0, |(_, c)| c)
        };
        assert!((weight(&dx, 2, 1) - 4.0 / 12.0).abs() < 1e-15);
        assert!((weight(&dx, 2, 0) - 1.0 / 12.0).abs() < 1e-15);
        assert!((weight(&dx, 0, 2) + 1.0 / 12.0).abs() < 1e-15);
        assert_eq!(weight(&dx, 1, 1), 0.0);
        // y up: the row above (row 0) enters with a plus sign.
        let dy = ops.dy(centre).unwrap();
        assert!((weight(&dy, 1, 0) - 4.0 / 12.0).abs() < 1e-15);
        assert!((weight(&dy, 1, 2) + 4.0 / 12.0).abs() < 1e-15);
        // Edge pixels fall back to one-sided differences.
        let corner = domain.at(0, 0).unwrap();
        let dxc = ops.dx(corner).unwrap();
        assert_eq!(weight(&dxc, 1, 0), 1.0);
        assert_eq!(weight(&dxc, 0, 0), -1.0);
    }

    #[test]
    fn isolated_pixel_has_no_derivatives() {
        let mask = Mask::from_fn(3, 3, |x, y| x == 1 && y == 1);
        let domain = Domain::new(&mask);
        let ops = Operators::new(&domain);
        assert!(ops.dx(0).is_none() && ops.dy(0).is_none() && ops.laplacian(0).is_none());
    }
}
