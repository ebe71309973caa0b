//! Materials: one file per lobe; this module combines them.
//!
//! Every Mueller matrix returned here is `f · cosθ_i` expressed in the two
//! *standard frames* of a shading point with normal `n`: output (light leaving
//! along `ω_o`) in the frame with x axis `s_axis(ω_o, n)`, input (light
//! arriving along `−ω_i`) in the frame with x axis `s_axis(−ω_i, n)`.
//! All lobes are rotated into these frames, so the integrator needs only them.

pub mod diffuse;
pub mod fresnel;
pub mod specular;

use crate::mueller::Mueller;
use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, PI};

/// `diffuse_polarized`: a dielectric with polarized subsurface diffuse
/// reflection and an optional GGX specular reflection lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// The grey albedo: a grey render's, and the one lobe choice reads.
    pub albedo: f32,
    /// The albedo of each colour channel (R, G, B) of a colour render.
    pub rgb: [f32; 3],
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

/// A material at one shading point and outgoing direction, with the terms
/// shared by all light and BSDF samples there computed once.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    material: Material,
    n: Vec3A,
    wo: Vec3A,
    /// Diffuse exit transmission terms at `θ_o` (see `diffuse`).
    exit: (f32, f32),
    /// Probability of sampling the specular lobe.
    p_specular: f32,
    alpha: f32,
}

impl Material {
    /// The albedo of each of `N` channels: the grey albedo when `N` is 1,
    /// else R, G, B.
    #[inline]
    pub fn albedos<const N: usize>(&self) -> [f32; N] {
        std::array::from_fn(|c| if N == 3 { self.rgb[c] } else { self.albedo })
    }

    /// The BSDF at normal `n` for light leaving towards `wo`; `None` when
    /// `wo` is below the surface.
    #[inline]
    pub fn at(&self, n: Vec3A, wo: Vec3A) -> Option<Bsdf> {
        let cos_o = n.dot(wo);
        if cos_o <= 0.0 {
            return None;
        }
        let exit = fresnel::transmission_terms(cos_o, self.eta);
        // Lobe choice ∝ the lobes' reflectances at ω_o, kept inside [0.1, 0.9]
        // when both exist.
        let p_specular = if self.specular <= 0.0 {
            0.0
        } else if self.albedo <= 0.0 {
            1.0
        } else {
            let t = exit.0;
            let spec = self.specular * (1.0 - t);
            (spec / (spec + self.albedo * t)).clamp(0.1, 0.9)
        };
        Some(Bsdf {
            material: *self,
            n,
            wo,
            exit,
            p_specular,
            alpha: self.roughness.max(specular::MIN_ALPHA),
        })
    }
}

impl Bsdf {
    /// `f · cosθ_i` for light arriving from `ω_i`, per channel
    /// ([`Material::albedos`]).
    #[inline]
    pub fn eval<const N: usize>(&self, wi: Vec3A) -> [Mueller; N] {
        let (diffuse, spec) = self.eval_lobes::<N>(wi);
        match spec {
            Some(spec) => diffuse.map(|d| d.add(&spec)),
            None => diffuse,
        }
    }

    /// `f · cosθ_i` of the diffuse lobe per channel and of the specular
    /// lobe (`None` without one; it keeps the light's colour), apart: the
    /// ground truth of the mixture (conventions.md §5,
    /// `gt/specular_stokes.exr`) needs the share of each.
    #[inline]
    pub fn eval_lobes<const N: usize>(&self, wi: Vec3A) -> ([Mueller; N], Option<Mueller>) {
        let m = &self.material;
        let cos_i = self.n.dot(wi);
        if cos_i <= 0.0 {
            return ([Mueller::ZERO; N], None);
        }
        let transfer = diffuse::transfer_with_exit(cos_i, self.exit, m.eta);
        let diffuse = m
            .albedos::<N>()
            .map(|albedo| transfer.scale(albedo * FRAC_1_PI * cos_i));
        if m.specular <= 0.0 {
            return (diffuse, None);
        }
        let spec = specular::eval(self.n, self.wo, wi, m.eta, self.alpha).scale(m.specular);
        (diffuse, Some(spec))
    }

    /// Whether the material has a specular lobe.
    #[inline]
    pub fn has_specular(&self) -> bool {
        self.material.specular > 0.0
    }

    /// Solid-angle density of [`Bsdf::sample`].
    #[inline]
    pub fn pdf(&self, wi: Vec3A) -> f32 {
        let cos_i = self.n.dot(wi);
        if cos_i <= 0.0 {
            return 0.0;
        }
        let p = self.p_specular;
        let mut pdf = (1.0 - p) * cos_i * FRAC_1_PI;
        if p > 0.0 {
            pdf += p * specular::pdf(self.n, self.wo, wi, self.alpha);
        }
        pdf
    }

    /// Picks a lobe with `u_lobe`, samples it with `u`, and weights by the
    /// full (all-lobe) value over the mixture density.
    #[inline]
    pub fn sample(&self, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let (wi, pdf) = self.sample_direction(u_lobe, u)?;
        Some(BsdfSample {
            wi,
            weight: self.weight::<1>(wi, pdf)[0],
            pdf,
        })
    }

    /// The direction and density of [`Bsdf::sample`] without its weight,
    /// for a path tracer that needs the weight only if the ray hits.
    #[inline]
    pub fn sample_direction(&self, u_lobe: f32, u: [f32; 2]) -> Option<(Vec3A, f32)> {
        let wi = if u_lobe < self.p_specular {
            specular::sample(self.n, self.wo, self.alpha, u)?
        } else {
            cosine_hemisphere(self.n, u)
        };
        let pdf = self.pdf(wi);
        (pdf > 0.0).then_some((wi, pdf))
    }

    /// The weight `f · cosθ_i / pdf` of a sampled direction, per channel.
    #[inline]
    pub fn weight<const N: usize>(&self, wi: Vec3A, pdf: f32) -> [Mueller; N] {
        self.eval::<N>(wi).map(|f| f.scale(pdf.recip()))
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
            rgb: [0.6; 3],
            eta: 1.5,
            specular: 0.8,
            roughness: 0.3,
        };
        let n = Vec3A::new(0.1, -0.2, 1.0).normalize();
        let wo = Vec3A::new(0.5, 0.2, 0.7).normalize();
        let count = 400_000;
        let mut s = Sampler::new(1, Stream::Path, 0, 0, 0);
        let (mut sampled, mut uniform) = ([0.0f64; 2], [0.0f64; 2]);
        let bsdf = m.at(n, wo).unwrap();
        for _ in 0..count {
            if let Some(bs) = bsdf.sample(s.next_f32(), s.next_2d()) {
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
            let c = bsdf.eval::<1>(wi)[0].column0();
            uniform[0] += f64::from(c[0]) * 2.0 * std::f64::consts::PI;
            uniform[1] += f64::from(c[1]) * 2.0 * std::f64::consts::PI;
        }
        for k in 0..2 {
            let (a, b) = (sampled[k] / count as f64, uniform[k] / count as f64);
            assert!((a - b).abs() < 0.01 * a.abs().max(0.05), "s{k}: {a} vs {b}");
        }
    }
}
