//! The per-pixel polarization model as a function of the surface gradient
//! `(p, q) = (∂z/∂x, ∂z/∂y)` (spec §3.1), with its derivatives for the
//! Jacobian rows: normal `n = (−p, −q, 1)/√(1+p²+q²)`, zenith `θ`,
//! azimuth `α = atan2(n_y, n_x)`, DoP `ρ(θ)` and phase `φ`.
//!
//! Specular pixels (spec Q1): the authors' code gives them the phase
//! `mod(α, π) + π`, which equals the diffuse phase, since the model reads
//! the phase only through `cos 2(ϑ − φ)`; their simulator (and physics,
//! conventions.md §3) turns specular polarization by 90°. The port gives
//! specular pixels the phase `α + π/2` ([`Reflection::Specular`]), so the
//! model and the data agree; the `authors_quirks` option keeps their phase
//! ([`Reflection::SpecularUnturned`]) for the comparison with their code.
//! Specular pixels enter only through a specular mask (`Observations`);
//! a view's `specular` option instead turns the measured AoP before the
//! method reads it, after which every pixel is read as diffuse.
//!
//! Derivatives are taken with respect to `(p, q)` directly. Near `p = q = 0`
//! the azimuth (and the zenith's direction of growth) is undefined; the
//! denominators carry [`EPSILON`], one value for both stages (the authors'
//! files use 1e-7, 1e-5 and none, spec Q8).

/// Regularises `|∇z|²` in the denominators of `∂α` and `∂θ`.
pub const EPSILON: f64 = 1e-7;

/// Zenith, azimuth and their gradients with respect to `(p, q)`.
#[derive(Clone, Copy, Debug)]
pub struct Angles {
    pub theta: f64,
    pub alpha: f64,
    pub dtheta: [f64; 2],
    pub dalpha: [f64; 2],
}

impl Angles {
    pub fn of(p: f64, q: f64) -> Angles {
        let g = p * p + q * q;
        let root = g.sqrt();
        let along = 1.0 / ((root + EPSILON) * (1.0 + g));
        let around = 1.0 / (g + EPSILON);
        Angles {
            theta: root.atan(),
            alpha: (-q).atan2(-p),
            dtheta: [p * along, q * along],
            dalpha: [-q * around, p * around],
        }
    }
}

/// Diffuse degree of polarization (conventions.md §3) and `dρ/dθ`.
pub fn diffuse_dop(theta: f64, eta: f64) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    let (a, b) = ((eta - 1.0 / eta).powi(2), (eta + 1.0 / eta).powi(2));
    let root = (eta * eta - s * s).sqrt();
    let num = a * s * s;
    let den = 2.0 + 2.0 * eta * eta - b * s * s + 4.0 * c * root;
    let dnum = 2.0 * a * s * c;
    // d/dθ of √(η² − sin²θ) is −sc/√(…).
    let dden = -2.0 * b * s * c - 4.0 * s * root - 4.0 * c * c * s / root;
    (num / den, (dnum * den - num * dden) / (den * den))
}

/// Specular degree of polarization, `(R_s − R_p)/(R_s + R_p)` written as in
/// the authors' code, and `dρ/dθ`.
pub fn specular_dop(theta: f64, eta: f64) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    let (s2, e2) = (s * s, eta * eta);
    let root = (e2 - s2).sqrt();
    let num = 2.0 * s2 * c * root;
    let den = e2 - s2 - e2 * s2 + 2.0 * s2 * s2;
    // d/dθ of s², c, root: 2sc, −s, −sc/root.
    let ds2 = 2.0 * s * c;
    let dnum = 2.0 * (ds2 * c * root - s2 * s * root - s2 * c * s * c / root);
    let dden = -ds2 - e2 * ds2 + 4.0 * s2 * ds2;
    (num / den, (dnum * den - num * dden) / (den * den))
}

/// How a pixel reflects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reflection {
    /// `ρ_d`, phase along the azimuth.
    Diffuse,
    /// `ρ_s`, phase across the azimuth.
    Specular,
    /// `ρ_s` with the diffuse phase: the authors' `+π` (Q1).
    SpecularUnturned,
}

/// What the model needs of one pixel: DoP and phase with their gradients.
#[derive(Clone, Copy, Debug)]
pub struct Pixel {
    pub rho: f64,
    pub phi: f64,
    pub drho: [f64; 2],
    pub dphi: [f64; 2],
}

impl Pixel {
    /// The model at gradient `(p, q)`, refractive index `eta`.
    pub fn of(p: f64, q: f64, eta: f64, reflection: Reflection) -> Pixel {
        let angles = Angles::of(p, q);
        let (rho, d) = match reflection {
            Reflection::Diffuse => diffuse_dop(angles.theta, eta),
            _ => specular_dop(angles.theta, eta),
        };
        let turn = match reflection {
            Reflection::Specular => std::f64::consts::FRAC_PI_2,
            _ => 0.0,
        };
        Pixel {
            rho,
            phi: angles.alpha + turn,
            drho: [d * angles.dtheta[0], d * angles.dtheta[1]],
            dphi: angles.dalpha,
        }
    }

    /// `f = 1 + ρ cos 2(ϑ − φ)` behind a polarizer at `vartheta` and its
    /// gradient with respect to `(p, q)`.
    pub fn transmitted(&self, vartheta: f64) -> (f64, [f64; 2]) {
        let (s, c) = (2.0 * (vartheta - self.phi)).sin_cos();
        let d = |i: usize| c * self.drho[i] + 2.0 * self.rho * s * self.dphi[i];
        (1.0 + self.rho * c, [d(0), d(1)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn numeric(f: impl Fn(f64) -> f64, x: f64) -> f64 {
        let h = 1e-6;
        (f(x + h) - f(x - h)) / (2.0 * h)
    }

    #[test]
    fn dop_derivatives_match_finite_differences() {
        for eta in [1.3, 1.5, 1.8] {
            for deg in [5.0, 30.0, 56.0, 75.0, 89.0_f64] {
                let t = deg.to_radians();
                let (rd, dd) = diffuse_dop(t, eta);
                assert!((rd - sfp_core::fresnel::diffuse_dop(t, eta)).abs() < 1e-12);
                assert!((dd - numeric(|t| diffuse_dop(t, eta).0, t)).abs() < 1e-6);
                let (rs, ds) = specular_dop(t, eta);
                assert!((rs - sfp_core::fresnel::specular_dop(t, eta)).abs() < 1e-9);
                assert!((ds - numeric(|t| specular_dop(t, eta).0, t)).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn angle_and_intensity_derivatives_match_finite_differences() {
        for (p, q) in [(0.3, -0.7), (-1.2, 0.4), (2.5, 1.5), (0.05, 0.02)] {
            let a = Angles::of(p, q);
            let n = [-p, -q, 1.0];
            let norm = (p * p + q * q + 1.0_f64).sqrt();
            assert!((a.theta - (n[2] / norm).acos()).abs() < 1e-12);
            assert!((a.alpha - n[1].atan2(n[0])).abs() < 1e-12);
            // Relative: EPSILON shifts the azimuth's derivative by ε/|∇z|².
            let close = |a: f64, b: f64| (a - b).abs() < 1e-4 * (1.0 + b.abs());
            assert!(close(a.dtheta[0], numeric(|p| Angles::of(p, q).theta, p)));
            assert!(close(a.dtheta[1], numeric(|q| Angles::of(p, q).theta, q)));
            assert!(close(a.dalpha[0], numeric(|p| Angles::of(p, q).alpha, p)));
            assert!(close(a.dalpha[1], numeric(|q| Angles::of(p, q).alpha, q)));
            for r in [Reflection::Diffuse, Reflection::Specular] {
                let m = Pixel::of(p, q, 1.5, r);
                let f = |p: f64, q: f64| Pixel::of(p, q, 1.5, r).transmitted(0.7).0;
                let (_, d) = m.transmitted(0.7);
                assert!(close(d[0], numeric(|p| f(p, q), p)));
                assert!(close(d[1], numeric(|q| f(p, q), q)));
            }
        }
    }

    #[test]
    fn specular_phase_is_turned_by_a_right_angle() {
        // The diffuse transmission peaks along the azimuth, the specular one
        // across it (the authors' `+π` would peak along it too).
        let (p, q) = (-0.5, -0.5);
        let alpha = Angles::of(p, q).alpha;
        let d = Pixel::of(p, q, 1.5, Reflection::Diffuse);
        let s = Pixel::of(p, q, 1.5, Reflection::Specular);
        let authors = Pixel::of(p, q, 1.5, Reflection::SpecularUnturned);
        assert!(d.transmitted(alpha).0 > d.transmitted(alpha + std::f64::consts::FRAC_PI_2).0);
        assert!(s.transmitted(alpha).0 < s.transmitted(alpha + std::f64::consts::FRAC_PI_2).0);
        assert!(authors.transmitted(alpha).0 > authors.transmitted(alpha + std::f64::consts::FRAC_PI_2).0);
    }
}
