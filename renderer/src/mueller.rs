//! Mueller matrices and Stokes reference frames, the way Mitsuba 3 handles them.
//!
//! A Stokes vector `(s0, s1, s2, s3)` of light travelling along `d` is expressed
//! in a frame `(x, y = d × x, d)`: `s1 = I_x − I_y`, `s2 = I_{+45°} − I_{−45°}`
//! with angles measured from `x` towards `y`. A frame is stored as its unit
//! `x` axis (perpendicular to `d`). For light reaching the camera
//! (`d = +z_cam`) and `x = +x_cam`, `y = +y_cam`: exactly the AoP convention of
//! conventions.md §1–2.
//!
//! Fresnel matrices are written in the *s/p frame* of an interface: `x` is the
//! `s` direction (perpendicular to the plane of incidence), `y` lies in it.

use glam::{Vec3A, Vec4};
use std::ops::Mul;

/// Stokes 4-vector `(s0, s1, s2, s3)`.
pub type Stokes4 = [f32; 4];

/// A 4×4 Mueller matrix, row-major.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mueller(pub [[f32; 4]; 4]);

impl Mueller {
    pub const IDENTITY: Mueller = Mueller([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);

    pub const ZERO: Mueller = Mueller([[0.0; 4]; 4]);

    /// Fresnel transmission or reflection in the s/p frame, from the power
    /// coefficients `(a_s, a_p)` (`T` or `R`) of the two polarizations:
    /// `I_s' = a_s I_s`, `I_p' = a_p I_p`, and the field phases are kept
    /// (`√(a_s a_p)` on `s2`, `s3`; for reflection below the critical angle the
    /// amplitude ratio is real, so the sign of `r_s r_p` sets that of `s2`, `s3`).
    pub fn fresnel(a_s: f32, a_p: f32, cross: f32) -> Mueller {
        let a = 0.5 * (a_s + a_p);
        let b = 0.5 * (a_s - a_p);
        Mueller([
            [a, b, 0.0, 0.0],
            [b, a, 0.0, 0.0],
            [0.0, 0.0, cross, 0.0],
            [0.0, 0.0, 0.0, cross],
        ])
    }

    /// `self · other`. Row `i` of the product is `Σ_k self[i][k] · other[k]`,
    /// summed in the order of [`Mueller::product_entry`] four lanes at a time
    /// (the same roundings: no fused multiply-add).
    #[inline]
    pub fn mul_matrix(&self, other: &Mueller) -> Mueller {
        let rows = other.0.map(Vec4::from_array);
        Mueller(self.0.map(|a| {
            (rows[0] * a[0] + rows[1] * a[1] + rows[2] * a[2] + rows[3] * a[3]).to_array()
        }))
    }

    /// Entry `(i, j)` of `self · other` alone, bit-identical to that of
    /// [`Mueller::mul_matrix`].
    #[inline]
    pub fn product_entry(&self, other: &Mueller, i: usize, j: usize) -> f32 {
        (0..4).map(|k| self.0[i][k] * other.0[k][j]).sum()
    }

    #[inline]
    pub fn apply(&self, s: Stokes4) -> Stokes4 {
        let m = &self.0;
        let row = |i: usize| m[i][0] * s[0] + m[i][1] * s[1] + m[i][2] * s[2] + m[i][3] * s[3];
        [row(0), row(1), row(2), row(3)]
    }

    /// The response to unpolarized light of unit intensity: the first column.
    #[inline]
    pub fn column0(&self) -> Stokes4 {
        [self.0[0][0], self.0[1][0], self.0[2][0], self.0[3][0]]
    }

    #[inline]
    pub fn scale(&self, k: f32) -> Mueller {
        Mueller(self.0.map(|row| (Vec4::from_array(row) * k).to_array()))
    }

    #[inline]
    pub fn add(&self, other: &Mueller) -> Mueller {
        let mut out = self.0;
        for (row, o) in out.iter_mut().zip(&other.0) {
            *row = (Vec4::from_array(*row) + Vec4::from_array(*o)).to_array();
        }
        Mueller(out)
    }

    /// Re-expresses a Stokes vector of light travelling along `d` from the
    /// frame with x axis `from` to the one with x axis `to` (both ⟂ `d`).
    ///
    /// With `α` the angle from `from` to `to` counter-clockwise about `d`, a
    /// polarization at angle `ψ` becomes `ψ − α`:
    /// `s1' = cos2α s1 + sin2α s2`, `s2' = −sin2α s1 + cos2α s2`.
    #[inline]
    pub fn rotation(d: Vec3A, from: Vec3A, to: Vec3A) -> Mueller {
        let (c2, s2) = double_angle(d, from, to);
        Mueller([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, c2, s2, 0.0],
            [0.0, -s2, c2, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// `self · rotation(d, from, to)` without the full product: a rotation only
    /// mixes columns 1 and 2.
    #[inline]
    pub fn then_rotated_input(&self, d: Vec3A, from: Vec3A, to: Vec3A) -> Mueller {
        let (c2, s2) = double_angle(d, from, to);
        let mut out = self.0;
        for row in out.iter_mut() {
            let (a, b) = (row[1], row[2]);
            row[1] = c2 * a - s2 * b;
            row[2] = s2 * a + c2 * b;
        }
        Mueller(out)
    }
}

impl Mul for Mueller {
    type Output = Mueller;
    fn mul(self, rhs: Mueller) -> Mueller {
        self.mul_matrix(&rhs)
    }
}

/// `(cos 2α, sin 2α)` of the angle from `from` to `to` about `d`.
#[inline]
fn double_angle(d: Vec3A, from: Vec3A, to: Vec3A) -> (f32, f32) {
    let c = from.dot(to);
    let s = from.cross(to).dot(d);
    let norm = c * c + s * s;
    if norm <= 0.0 {
        return (1.0, 0.0);
    }
    ((c * c - s * s) / norm, 2.0 * c * s / norm)
}

/// Some unit vector perpendicular to `d` (for frames where any will do).
#[inline]
pub fn perpendicular(d: Vec3A) -> Vec3A {
    d.any_orthonormal_vector()
}

/// The `s` axis of the s/p frame for light travelling along `d` across an
/// interface with normal `n`: perpendicular to the plane of incidence.
/// At normal incidence every axis is equivalent; one is picked from `d`
/// alone so that all callers agree.
#[inline]
pub fn s_axis(d: Vec3A, n: Vec3A) -> Vec3A {
    let s = d.cross(n);
    let len2 = s.length_squared();
    if len2 < 1e-12 {
        perpendicular(d)
    } else {
        s * len2.sqrt().recip()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Stokes4, b: Stokes4) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-6)
    }

    /// Stokes of fully linearly polarized light whose field lies along `e`,
    /// computed directly from the projection onto the frame axes.
    fn linear_along(e: Vec3A, d: Vec3A, x: Vec3A) -> Stokes4 {
        let y = d.cross(x);
        let (ex, ey) = (e.dot(x), e.dot(y));
        [ex * ex + ey * ey, ex * ex - ey * ey, 2.0 * ex * ey, 0.0]
    }

    #[test]
    fn rotation_matches_direct_projection() {
        let d = Vec3A::new(0.3, -0.2, 0.9).normalize();
        let a = perpendicular(d);
        let b = d.cross(a);
        for k in 0..12 {
            let alpha = 0.37 * k as f32;
            let to = a * alpha.cos() + b * alpha.sin();
            let e = a * 0.8f32.cos() + b * 0.8f32.sin();
            let before = linear_along(e, d, a);
            let after = Mueller::rotation(d, a, to).apply(before);
            assert!(close(after, linear_along(e, d, to)), "α={alpha}");
            let via_product = Mueller::IDENTITY.then_rotated_input(d, a, to).apply(before);
            assert!(close(via_product, after));
        }
    }

    #[test]
    fn product_is_the_row_by_column_sum() {
        let a = Mueller(std::array::from_fn(|i| {
            std::array::from_fn(|j| (i * 4 + j) as f32 * 0.37 - 2.1)
        }));
        let b = Mueller(std::array::from_fn(|i| {
            std::array::from_fn(|j| 1.3 / (1.0 + (i + 2 * j) as f32) - 0.4)
        }));
        let p = a.mul_matrix(&b);
        for i in 0..4 {
            for j in 0..4 {
                let direct: f32 = (0..4).map(|k| a.0[i][k] * b.0[k][j]).sum();
                assert_eq!(p.0[i][j], direct);
                assert_eq!(a.product_entry(&b, i, j), direct);
            }
        }
        assert_eq!(Mueller::IDENTITY.mul_matrix(&b), b);
        let (sum, scaled) = (a.add(&b), a.scale(-0.5));
        for i in 0..4 {
            for j in 0..4 {
                assert_eq!(sum.0[i][j], a.0[i][j] + b.0[i][j]);
                assert_eq!(scaled.0[i][j], a.0[i][j] * -0.5);
            }
        }
    }

    #[test]
    fn fresnel_matrix_scales_s_and_p() {
        let m = Mueller::fresnel(0.5, 0.9, (0.45f32).sqrt());
        // Pure s (x) light and pure p (y) light.
        let s = m.apply([1.0, 1.0, 0.0, 0.0]);
        let p = m.apply([1.0, -1.0, 0.0, 0.0]);
        assert!(close(s, [0.5, 0.5, 0.0, 0.0]) && close(p, [0.9, -0.9, 0.0, 0.0]));
    }

    #[test]
    fn s_axis_is_perpendicular_to_plane_of_incidence() {
        let n = Vec3A::new(0.2, 0.5, 0.8).normalize();
        let d = Vec3A::new(-0.1, 0.0, 1.0).normalize();
        let s = s_axis(d, n);
        assert!(s.dot(n).abs() < 1e-6 && s.dot(d).abs() < 1e-6);
        assert!((s.length() - 1.0).abs() < 1e-6);
        assert!((s_axis(n, n).length() - 1.0).abs() < 1e-6);
    }
}
