//! Linear Stokes parameters from polarizer images, and the derived unpolarized
//! intensity, degree of polarization and angle of polarization
//! (conventions.md §2; note the paper's Eq. 3 AoP erratum).
//!
//! Polarizer angles and AoP are measured from camera `+x` towards `+y` (up).

use crate::{Error, Image, Result};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The four standard polarizer angles, in radians, in file order
/// (`pol_000`, `pol_045`, `pol_090`, `pol_135`).
pub const STANDARD_ANGLES: [f64; 4] = [0.0, PI / 4.0, PI / 2.0, 3.0 * PI / 4.0];

/// Linear Stokes vector `(s0, s1, s2)`; circular polarization is not observed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stokes {
    pub s0: f64,
    pub s1: f64,
    pub s2: f64,
}

impl Stokes {
    pub fn new(s0: f64, s1: f64, s2: f64) -> Self {
        Stokes { s0, s1, s2 }
    }

    /// Light of intensity `s0`, degree `dop` and angle `aop` of polarization.
    pub fn from_polarization(s0: f64, dop: f64, aop: f64) -> Self {
        Stokes {
            s0,
            s1: s0 * dop * (2.0 * aop).cos(),
            s2: s0 * dop * (2.0 * aop).sin(),
        }
    }

    /// From the four standard polarizer images. `s0` is the least-squares
    /// estimate `½ΣI`, which equals `I0 + I90` without noise.
    pub fn from_four(i0: f64, i45: f64, i90: f64, i135: f64) -> Self {
        Stokes {
            s0: 0.5 * (i0 + i45 + i90 + i135),
            s1: i0 - i90,
            s2: i45 - i135,
        }
    }

    /// Intensity behind an ideal linear polarizer at `angle`:
    /// `I(ϑ) = ½(s0 + s1 cos 2ϑ + s2 sin 2ϑ)`.
    pub fn through_polarizer(&self, angle: f64) -> f64 {
        0.5 * (self.s0 + self.s1 * (2.0 * angle).cos() + self.s2 * (2.0 * angle).sin())
    }

    /// Unpolarized intensity `I_un = s0 / 2`.
    pub fn unpolarized(&self) -> f64 {
        0.5 * self.s0
    }

    /// Degree of linear polarization, clamped to `[0, 1]`; 0 when `s0 ≤ 0`.
    pub fn dop(&self) -> f64 {
        if self.s0 <= 0.0 {
            return 0.0;
        }
        (self.s1.hypot(self.s2) / self.s0).clamp(0.0, 1.0)
    }

    /// Degree of linear polarization without clamping (for detecting DoP > 1).
    pub fn dop_unclamped(&self) -> f64 {
        self.s1.hypot(self.s2) / self.s0
    }

    /// Angle of polarization `½ atan2(s2, s1)` wrapped to `[0, π)`.
    pub fn aop(&self) -> f64 {
        wrap_aop(0.5 * self.s2.atan2(self.s1))
    }
}

/// Wraps an angle to `[0, π)`: AoP and polarizer angles are axial.
pub fn wrap_aop(angle: f64) -> f64 {
    let w = angle.rem_euclid(PI);
    // rem_euclid can return exactly PI for tiny negative inputs due to rounding.
    if w >= PI { 0.0 } else { w }
}

/// Least-squares Stokes estimator for `N ≥ 3` arbitrary polarizer angles.
///
/// Precomputes the pseudo-inverse of the `N × 3` design matrix
/// `[½, ½cos2ϑ, ½sin2ϑ]`, so per-pixel use is a 3×N product.
#[derive(Clone, Debug)]
pub struct StokesFit {
    pinv: Vec<[f64; 3]>,
}

impl StokesFit {
    /// Fails when fewer than 3 angles are given or they do not determine the
    /// Stokes vector (e.g. all angles equal modulo π).
    pub fn new(angles: &[f64]) -> Result<Self> {
        if angles.len() < 3 {
            return Err(Error::invalid(format!(
                "{} polarizer angles given, at least 3 are needed",
                angles.len()
            )));
        }
        let rows: Vec<[f64; 3]> = angles
            .iter()
            .map(|&a| [0.5, 0.5 * (2.0 * a).cos(), 0.5 * (2.0 * a).sin()])
            .collect();
        let mut ata = [[0.0; 3]; 3];
        for r in &rows {
            for i in 0..3 {
                for j in 0..3 {
                    ata[i][j] += r[i] * r[j];
                }
            }
        }
        let inv = invert3(&ata).ok_or_else(|| {
            Error::invalid("polarizer angles do not determine the Stokes vector (need 3 distinct angles modulo 180°)")
        })?;
        let pinv = rows
            .iter()
            .map(|r| {
                let mut c = [0.0; 3];
                for (i, ci) in c.iter_mut().enumerate() {
                    *ci = (0..3).map(|j| inv[i][j] * r[j]).sum();
                }
                c
            })
            .collect();
        Ok(StokesFit { pinv })
    }

    /// Stokes vector from intensities in the order of the angles given to `new`.
    pub fn fit(&self, intensities: &[f64]) -> Stokes {
        debug_assert_eq!(intensities.len(), self.pinv.len());
        let mut s = [0.0; 3];
        for (c, &v) in self.pinv.iter().zip(intensities) {
            for k in 0..3 {
                s[k] += c[k] * v;
            }
        }
        Stokes::new(s[0], s[1], s[2])
    }
}

fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    if det.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = c(j, i) / det;
        }
    }
    Some(inv)
}

/// Per-pixel polarimetric quantities the reconstruction methods consume.
#[derive(Clone, Debug)]
pub struct Polarimetry {
    /// Unpolarized intensity `I_un = s0/2`.
    pub intensity: Image<f32>,
    /// Degree of linear polarization in `[0, 1]`.
    pub dop: Image<f32>,
    /// Angle of polarization in `[0, π)`.
    pub aop: Image<f32>,
}

impl Polarimetry {
    /// From Stokes images `s0, s1, s2` of equal size.
    pub fn from_stokes(s: &[Image<f32>; 3]) -> Self {
        let (w, h) = s[0].size();
        Self::from_fn(w, h, |i| {
            Stokes::new(
                f64::from(s[0].data()[i]),
                f64::from(s[1].data()[i]),
                f64::from(s[2].data()[i]),
            )
        })
    }

    /// From the Stokes vector of each pixel (row-major index), computed in
    /// parallel: sweeps derive it for every noise realisation.
    pub(crate) fn from_fn(w: usize, h: usize, stokes: impl Fn(usize) -> Stokes + Sync) -> Self {
        let mut p = Polarimetry {
            intensity: Image::new(w, h, 0.0),
            dop: Image::new(w, h, 0.0),
            aop: Image::new(w, h, 0.0),
        };
        p.intensity
            .data_mut()
            .par_iter_mut()
            .zip(p.dop.data_mut())
            .zip(p.aop.data_mut())
            .enumerate()
            .for_each(|(i, ((intensity, dop), aop))| {
                let st = stokes(i);
                *intensity = st.unpolarized() as f32;
                *dop = st.dop() as f32;
                *aop = st.aop() as f32;
            });
        p
    }
}

/// Stokes images `(s0, s1, s2)` from the four standard polarizer images.
pub fn stokes_from_four(pol: &[Image<f32>; 4]) -> Result<[Image<f32>; 3]> {
    let size = pol[0].size();
    if pol.iter().any(|p| p.size() != size) {
        return Err(Error::invalid("polarizer images differ in size"));
    }
    let n = pol[0].len();
    let mut s = [
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    ];
    for i in 0..n {
        let v = |k: usize| f64::from(pol[k].data()[i]);
        let st = Stokes::from_four(v(0), v(1), v(2), v(3));
        s[0].push(st.s0 as f32);
        s[1].push(st.s1 as f32);
        s[2].push(st.s2 as f32);
    }
    let [a, b, c] = s;
    Ok([
        Image::from_vec(size.0, size.1, a)?,
        Image::from_vec(size.0, size.1, b)?,
        Image::from_vec(size.0, size.1, c)?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    #[test]
    fn four_angle_recovery_of_random_stokes() {
        let mut rng = Pcg64::seed_from_u64(1);
        for _ in 0..10_000 {
            let s0: f64 = rng.random_range(0.01..10.0);
            let dop: f64 = rng.random_range(0.0..1.0);
            let aop: f64 = rng.random_range(0.0..PI);
            let s = Stokes::from_polarization(s0, dop, aop);
            let i: Vec<f64> = STANDARD_ANGLES
                .iter()
                .map(|&a| s.through_polarizer(a))
                .collect();
            let r = Stokes::from_four(i[0], i[1], i[2], i[3]);
            assert!((r.s0 - s.s0).abs() < 1e-12 * s0);
            assert!((r.s1 - s.s1).abs() < 1e-12 * s0);
            assert!((r.s2 - s.s2).abs() < 1e-12 * s0);
            assert!((r.dop() - dop).abs() < 1e-9);
            if dop > 1e-6 {
                let d = (r.aop() - aop).abs();
                assert!(d.min(PI - d) < 1e-6, "aop {} vs {aop}", r.aop());
            }
        }
    }

    #[test]
    fn arbitrary_angle_least_squares_recovers_stokes() {
        let mut rng = Pcg64::seed_from_u64(2);
        for n in 3..8 {
            let angles: Vec<f64> = (0..n).map(|k| k as f64 * PI / n as f64 + 0.1).collect();
            let fit = StokesFit::new(&angles).unwrap();
            for _ in 0..1000 {
                let s = Stokes::new(
                    rng.random_range(1.0..5.0),
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                );
                let i: Vec<f64> = angles.iter().map(|&a| s.through_polarizer(a)).collect();
                let r = fit.fit(&i);
                assert!((r.s0 - s.s0).abs() < 1e-12);
                assert!((r.s1 - s.s1).abs() < 1e-12);
                assert!((r.s2 - s.s2).abs() < 1e-12);
            }
        }
        // The four standard angles give the same estimate as the closed form.
        let fit = StokesFit::new(&STANDARD_ANGLES).unwrap();
        let r = fit.fit(&[0.3, 0.7, 0.2, 0.1]);
        let c = Stokes::from_four(0.3, 0.7, 0.2, 0.1);
        assert!((r.s0 - c.s0).abs() < 1e-12 && (r.s1 - c.s1).abs() < 1e-12);
    }

    #[test]
    fn degenerate_angle_sets_are_rejected() {
        assert!(StokesFit::new(&[0.0, 1.0]).is_err());
        assert!(StokesFit::new(&[0.0, PI, 2.0 * PI]).is_err());
    }

    #[test]
    fn aop_wraps_at_zero_and_pi() {
        assert_eq!(wrap_aop(0.0), 0.0);
        assert_eq!(wrap_aop(PI), 0.0);
        assert!((wrap_aop(-1e-9) - (PI - 1e-9)).abs() < 1e-15);
        assert!(wrap_aop(-1e-300) < PI);
        assert!((wrap_aop(PI + 0.25) - 0.25).abs() < 1e-15);
        // Polarization at ±ε around 0° reports angles just above 0 and just below π.
        let up = Stokes::from_polarization(1.0, 0.5, 1e-4).aop();
        let down = Stokes::from_polarization(1.0, 0.5, -1e-4).aop();
        assert!((up - 1e-4).abs() < 1e-12);
        assert!((down - (PI - 1e-4)).abs() < 1e-12);
        // Vertical polarization (s1 < 0, s2 = 0) is 90°, and the erratum's
        // tan⁻¹(s1/s2)/2 would be wrong here.
        let v = Stokes::new(1.0, -0.5, 0.0).aop();
        assert!((v - PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn dop_of_dark_pixel_is_zero() {
        assert_eq!(Stokes::new(0.0, 0.0, 0.0).dop(), 0.0);
    }
}
