//! The mixed reflection model as a function of a height field's gradient:
//! what the surface fit (`fit`) explains the measured polarization with.
//!
//! A share `f` of `s0` reflected at the surface, polarized across the
//! normal's azimuth with the specular DoP `ρ_s(θ)`, and the rest
//! transmitted out of it, polarized along the azimuth with the diffuse DoP
//! `ρ_d(θ)` (conventions.md §3), give the normalised linear Stokes vector
//! `(s1, s2)/s0 = ((1 − f) ρ_d(θ) − f ρ_s(θ)) (cos 2φ, sin 2φ)`.
//!
//! With the gradient `(p, q) = (z_x, z_y)` (conventions.md §1), `u = p² + q²`
//! and `sin²θ = u / (1 + u)`, the azimuth's double angle is
//! `(cos 2φ, sin 2φ) = (p² − q², 2pq) / u`, so the model is
//! `m = G(u) (p² − q², 2pq)` with `G(u) = ((1 − f) R_d − f R_s) / (1 + u)`,
//! where `R = ρ / sin²θ`. Both DoPs vanish like `sin²θ` at normal
//! incidence, so `G` is smooth there and the model has no singularity at a
//! surface facing the camera (where `φ` is undefined). The model is even in
//! `(p, q)`: the fit, like the data, cannot tell a normal's sense.

/// `ρ_d / sin²θ` at `s = sin²θ`: conventions.md §3's diffuse DoP with its
/// factor `sin²θ` taken out.
fn diffuse_ratio(s: f64, eta: f64) -> f64 {
    let c = (1.0 - s).max(0.0).sqrt();
    let a = eta - 1.0 / eta;
    let b = eta + 1.0 / eta;
    a * a / (2.0 + 2.0 * eta * eta - b * b * s + 4.0 * c * (eta * eta - s).sqrt())
}

/// `ρ_s / sin²θ` at `s = sin²θ`: the specular DoP (`fresnel::specular_dop`)
/// with its factor `sin²θ` taken out.
fn specular_ratio(s: f64, eta: f64) -> f64 {
    let c = (1.0 - s).max(0.0).sqrt();
    let e2 = eta * eta;
    2.0 * c * (e2 - s).sqrt() / (e2 - s - e2 * s + 2.0 * s * s)
}

/// The model at one pixel: specular share `share` of `s0`, refractive index
/// `eta`.
#[derive(Clone, Copy, Debug)]
pub struct Mixture {
    pub share: f64,
    pub eta: f64,
}

/// The model's normalised Stokes vector at a gradient and its derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polarization {
    /// `(s1, s2) / s0`.
    pub value: [f64; 2],
    /// `∂value[i] / ∂(p, q)[j]`.
    pub jacobian: [[f64; 2]; 2],
}

impl Mixture {
    /// `G(u)` of the module doc.
    fn gain(&self, u: f64) -> f64 {
        let s = u / (1.0 + u);
        let f = self.share;
        ((1.0 - f) * diffuse_ratio(s, self.eta) - f * specular_ratio(s, self.eta)) / (1.0 + u)
    }

    /// The model at gradient `(p, q)` with its Jacobian. `G′` is a central
    /// difference: `G` is smooth and the step's error (~1e-10 relative) is
    /// far below any sensor's noise.
    pub fn at(&self, p: f64, q: f64) -> Polarization {
        let u = p * p + q * q;
        let g = self.gain(u);
        let h = 1e-5 * (1.0 + u);
        let dg = (self.gain(u + h) - self.gain((u - h).max(0.0))) / (u + h - (u - h).max(0.0));
        let (a, b) = (p * p - q * q, 2.0 * p * q);
        Polarization {
            value: [g * a, g * b],
            jacobian: [
                [2.0 * p * (dg * a + g), 2.0 * q * (dg * a - g)],
                [
                    2.0 * p * dg * b + 2.0 * g * q,
                    2.0 * q * dg * b + 2.0 * g * p,
                ],
            ],
        }
    }
}

/// The diffuse and specular DoPs at gradient `(p, q)`: what a pixel's
/// specular share is read against (`share::share_of`).
pub fn dops(p: f64, q: f64, eta: f64) -> (f64, f64) {
    let u = p * p + q * q;
    let s = u / (1.0 + u);
    (s * diffuse_ratio(s, eta), s * specular_ratio(s, eta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_core::fresnel::{diffuse_dop, specular_dop};

    #[test]
    fn the_ratios_are_the_dops_over_sin_squared() {
        for eta in [1.3, 1.5, 1.8] {
            for deg in [1.0, 20.0, 45.0, 56.0, 70.0, 89.0] {
                let theta = f64::to_radians(deg);
                let s = theta.sin().powi(2);
                let d = s * diffuse_ratio(s, eta) - diffuse_dop(theta, eta);
                let r = s * specular_ratio(s, eta) - specular_dop(theta, eta);
                assert!(d.abs() < 1e-12 && r.abs() < 1e-12, "{eta} {deg}: {d} {r}");
            }
        }
    }

    #[test]
    fn the_model_is_the_mixture_along_the_azimuth() {
        let m = Mixture {
            share: 0.3,
            eta: 1.6,
        };
        // A normal of zenith 50° and azimuth 130°.
        let (theta, phi) = (50f64.to_radians(), 130f64.to_radians());
        let t = theta.tan();
        let (p, q) = (-t * phi.cos(), -t * phi.sin());
        let want = 0.7 * diffuse_dop(theta, 1.6) - 0.3 * specular_dop(theta, 1.6);
        let got = m.at(p, q).value;
        let expect = [want * (2.0 * phi).cos(), want * (2.0 * phi).sin()];
        for i in 0..2 {
            assert!((got[i] - expect[i]).abs() < 1e-12, "{got:?} {expect:?}");
        }
        // Facing the camera: unpolarized, and a finite Jacobian.
        let flat = m.at(0.0, 0.0);
        assert_eq!(flat.value, [0.0, 0.0]);
        assert!(flat.jacobian.iter().flatten().all(|v| v.is_finite()));
    }

    #[test]
    fn the_jacobian_matches_finite_differences() {
        let m = Mixture {
            share: 0.15,
            eta: 1.5,
        };
        for (p, q) in [(0.3, -0.2), (-1.4, 0.6), (0.05, 0.02), (3.0, 2.0)] {
            let j = m.at(p, q).jacobian;
            let h = 1e-6;
            for (k, (dp, dq)) in [(h, 0.0), (0.0, h)].into_iter().enumerate() {
                let plus = m.at(p + dp, q + dq).value;
                let minus = m.at(p - dp, q - dq).value;
                for i in 0..2 {
                    let numeric = (plus[i] - minus[i]) / (2.0 * h);
                    let err = (numeric - j[i][k]).abs();
                    assert!(
                        err < 1e-6 * (1.0 + numeric.abs()),
                        "({p}, {q}) [{i}][{k}]: {err}"
                    );
                }
            }
        }
    }
}
