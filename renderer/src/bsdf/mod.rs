//! Materials: one file per lobe; this module combines them.
//!
//! Every Mueller matrix returned here is `f · cosθ_i` expressed in the two
//! *standard frames* of a shading point with normal `n`: output (light leaving
//! along `ω_o`) in the frame with x axis `s_axis(ω_o, n)`, input (light
//! arriving along `−ω_i`) in the frame with x axis `s_axis(−ω_i, n)`.
//! All lobes are rotated into these frames, so the integrator needs only them.

pub mod diffuse_polarized;
pub mod specular;

use crate::mueller::Mueller;
use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, PI};

/// `diffuse_polarized`: a dielectric with polarized subsurface diffuse
/// reflection and an optional GGX specular reflection lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub albedo: f32,
    pub eta: f32,
    /// Weight of the specular lobe (0 = pure diffuse).
    pub specular: f32,
    /// GGX `α` of the specular lobe.
    pub roughness: f32,
}

/// A sampled incident direction with `f · cosθ_i / pdf` and the pdf.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3A,
    pub weight: Mueller,
    pub pdf: f32,
}

impl Material {
    fn alpha(&self) -> f32 {
        self.roughness.max(specular::MIN_ALPHA)
    }

    /// Probability of sampling the specular lobe: proportional to the lobes'
    /// rough reflectances at `ω_o`, kept away from 0 and 1 when both exist.
    fn specular_probability(&self, cos_o: f32) -> f32 {
        if self.specular <= 0.0 {
            return 0.0;
        }
        if self.albedo <= 0.0 {
            return 1.0;
        }
        let (rs, rp) = sfp_core::fresnel::reflectance(f64::from(cos_o), f64::from(self.eta));
        let r = 0.5 * (rs + rp) as f32;
        let spec = self.specular * r;
        (spec / (spec + self.albedo * (1.0 - r))).clamp(0.1, 0.9)
    }

    /// `f · cosθ_i` for light arriving from `ω_i` and leaving towards `ω_o`.
    pub fn eval(&self, n: Vec3A, wo: Vec3A, wi: Vec3A) -> Mueller {
        let (cos_o, cos_i) = (n.dot(wo), n.dot(wi));
        if cos_o <= 0.0 || cos_i <= 0.0 {
            return Mueller::ZERO;
        }
        let diffuse = diffuse_polarized::transfer(cos_i, cos_o, self.eta)
            .scale(self.albedo * FRAC_1_PI * cos_i);
        if self.specular <= 0.0 {
            return diffuse;
        }
        let spec = specular::eval(n, wo, wi, self.eta, self.alpha()).scale(self.specular);
        diffuse.add(&spec)
    }

    /// Solid-angle density of [`Material::sample`].
    pub fn pdf(&self, n: Vec3A, wo: Vec3A, wi: Vec3A) -> f32 {
        let (cos_o, cos_i) = (n.dot(wo), n.dot(wi));
        if cos_o <= 0.0 || cos_i <= 0.0 {
            return 0.0;
        }
        let p = self.specular_probability(cos_o);
        let mut pdf = (1.0 - p) * cos_i * FRAC_1_PI;
        if p > 0.0 {
            pdf += p * specular::pdf(n, wo, wi, self.alpha());
        }
        pdf
    }

    /// Picks a lobe with `u_lobe`, samples it with `u`, and weights by the
    /// full (all-lobe) value over the mixture density.
    pub fn sample(&self, n: Vec3A, wo: Vec3A, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let cos_o = n.dot(wo);
        if cos_o <= 0.0 {
            return None;
        }
        let p = self.specular_probability(cos_o);
        let wi = if u_lobe < p {
            specular::sample(n, wo, self.alpha(), u)?
        } else {
            cosine_hemisphere(n, u)
        };
        let pdf = self.pdf(n, wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.eval(n, wo, wi).scale(pdf.recip()),
            pdf,
        })
    }
}

/// Cosine-weighted direction about `n` (density `cosθ/π`).
#[inline]
pub fn cosine_hemisphere(n: Vec3A, u: [f32; 2]) -> Vec3A {
    let (t, b) = n.any_orthonormal_pair();
    let r = u[0].sqrt();
    let phi = 2.0 * PI * u[1];
    let z = (1.0 - u[0]).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, Stream};

    /// `E[weight] = ∫ f cosθ_i dω` must not depend on how lobes are sampled:
    /// compare the sampled estimate with a uniform-hemisphere estimate.
    #[test]
    fn sampling_weight_is_unbiased() {
        let m = Material {
            albedo: 0.6,
            eta: 1.5,
            specular: 0.8,
            roughness: 0.3,
        };
        let n = Vec3A::new(0.1, -0.2, 1.0).normalize();
        let wo = Vec3A::new(0.5, 0.2, 0.7).normalize();
        let count = 400_000;
        let mut s = Sampler::new(1, Stream::Path, 0, 0, 0);
        let (mut sampled, mut uniform) = ([0.0f64; 2], [0.0f64; 2]);
        for _ in 0..count {
            if let Some(bs) = m.sample(n, wo, s.next_f32(), s.next_2d()) {
                let c = bs.weight.column0();
                sampled[0] += f64::from(c[0]);
                sampled[1] += f64::from(c[1]);
            }
            // Uniform hemisphere: pdf 1/(2π).
            let [u0, u1] = s.next_2d();
            let z = u0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let (t, b) = n.any_orthonormal_pair();
            let phi = 2.0 * PI * u1;
            let wi = t * (r * phi.cos()) + b * (r * phi.sin()) + n * z;
            let c = m.eval(n, wo, wi).column0();
            uniform[0] += f64::from(c[0]) * 2.0 * std::f64::consts::PI;
            uniform[1] += f64::from(c[1]) * 2.0 * std::f64::consts::PI;
        }
        for k in 0..2 {
            let (a, b) = (sampled[k] / count as f64, uniform[k] / count as f64);
            assert!((a - b).abs() < 0.01 * a.abs().max(0.05), "s{k}: {a} vs {b}");
        }
    }
}
