//! The full stage's light or albedo, estimated once in closed form from
//! the ratio stage's surface (spec §4.2): each polarizer image divided by
//! the surface's polarization factor `1 + ρ cos 2(ϑ_j − α)` estimates the
//! unpolarized intensity `u_j` at every pixel where it is positive. With a
//! uniform albedo, the light is the mean over images of the least-squares
//! `n · L_j ≈ u_j`; with a known light `s`, each pixel's albedo is the mean
//! over images of `u_j / n·s`, counting 0 for images where it is shadowed.
//! The port also counts a pixel facing away from the known light
//! (`n·s ≤ 0`) as shadowed, where the authors' division has no bound.

use super::full::Shading;
use super::level::Level;
use super::model::{Pixel, Reflection};
use sfp_core::{Error, Result};

/// Unit normal and polarization factor per image of unknown `k` at `z`.
fn sample(level: &Level, z: &[f64], k: usize) -> ([f64; 3], Pixel) {
    let (p, q) = level.gradients.at(k, z);
    let norm = (1.0 + p * p + q * q).sqrt();
    ([-p / norm, -q / norm, 1.0 / norm], Pixel::of(p, q, level.eta, Reflection::Diffuse))
}

/// The uniform-albedo light `L` (it carries albedo and intensity scale).
pub fn estimate_light(level: &Level, z: &[f64]) -> Result<Shading> {
    let count = level.angle_count();
    let mut mean = [0.0; 3];
    for j in 0..count {
        let (mut ata, mut atb) = ([[0.0; 3]; 3], [0.0; 3]);
        for k in 0..level.domain.len() {
            let (n, model) = sample(level, z, k);
            let u = level.intensities[k * count + j] / model.transmitted(level.angles[j]).0;
            if u > 0.0 {
                for a in 0..3 {
                    atb[a] += n[a] * u;
                    for b in 0..3 {
                        ata[a][b] += n[a] * n[b];
                    }
                }
            }
        }
        let l = solve3(ata, atb).ok_or_else(|| {
            Error::invalid("yu2017: too few lit pixels with distinct normals to estimate the light")
        })?;
        (0..3).for_each(|a| mean[a] += l[a] / count as f64);
    }
    Ok(Shading {
        light: mean,
        albedo: None,
    })
}

/// Each pixel's albedo under the known light `s`.
pub fn estimate_albedo(level: &Level, z: &[f64], s: [f64; 3]) -> Shading {
    let count = level.angle_count();
    let albedo = (0..level.domain.len())
        .map(|k| {
            let (n, model) = sample(level, z, k);
            let ns = n[0] * s[0] + n[1] * s[1] + n[2] * s[2];
            (0..count)
                .map(|j| {
                    let u = level.intensities[k * count + j] / model.transmitted(level.angles[j]).0;
                    if u > 0.0 && ns > 0.0 { u / ns } else { 0.0 }
                })
                .sum::<f64>()
                / count as f64
        })
        .collect();
    Shading {
        light: s,
        albedo: Some(albedo),
    }
}

/// `A x = b` for a symmetric 3×3 `A` (Cramer), `None` when singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let scale = a.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max).powi(3);
    if d.abs() <= 1e-12 * scale || d.is_nan() {
        return None;
    }
    let mut x = [0.0; 3];
    for (c, xc) in x.iter_mut().enumerate() {
        let mut m = a;
        (0..3).for_each(|r| m[r][c] = b[r]);
        *xc = det(m) / d;
    }
    Some(x)
}
