//! One level of the coarse-to-fine pyramid: the observations decimated to
//! every `step`-th pixel (as the authors do, without low-pass filtering),
//! the refined mask, its unknowns, stencils and layer prior.

use super::layers::layers;
use super::model::Reflection;
use super::refine::refine;
use super::stencils::{Gradients, laplacian};
use crate::solver::domain::Domain;
use crate::solver::operators::Stencil;
use sfp_core::{Image, Mask};

/// Polarizer images of one object and what is known of its pixels.
#[derive(Clone, Debug)]
pub struct Observations {
    /// Polarizer angles in radians, camera frame (conventions.md §1).
    pub angles: Vec<f64>,
    /// One image per angle, linear intensities (16-bit full scale is what
    /// the weights assume: the full stage's residuals are intensities).
    pub images: Vec<Image<f64>>,
    pub mask: Mask,
    /// Pixels read with the specular model (`model::Pixel`).
    pub specular: Mask,
}

/// A layer pixel of the outward-normal prior, by unknown.
#[derive(Clone, Copy, Debug)]
pub struct Target {
    pub unknown: usize,
    pub azimuth: f64,
    pub weight: f64,
}

/// What both stages read at one pyramid level.
pub struct Level {
    pub step: usize,
    pub domain: Domain,
    pub gradients: Gradients,
    pub laplacians: Vec<Stencil>,
    /// `angles.len()` intensities per unknown, unknown after unknown.
    pub intensities: Vec<f64>,
    pub angles: Vec<f64>,
    pub specular: Vec<bool>,
    pub targets: Vec<Target>,
    pub eta: f64,
    /// The authors' specular phase (Q1) and residual 1 for an unusable
    /// ratio (`ratio`) instead of the port's.
    pub authors_quirks: bool,
}

impl Level {
    /// The level of every `step`-th pixel of `obs` (`None` when its refined
    /// mask is empty); `authors_quirks` keeps their specular phase (Q1),
    /// Laplacian (Q3), spur tips and junction means (`layers`).
    pub fn new(obs: &Observations, step: usize, eta: f64, authors_quirks: bool) -> Option<Level> {
        let (w, h) = obs.mask.size();
        let (lw, lh) = (w.div_ceil(step), h.div_ceil(step));
        let mask = refine(&Mask::from_fn(lw, lh, |x, y| *obs.mask.get(x * step, y * step)));
        if mask.count() == 0 {
            return None;
        }
        let domain = Domain::new(&mask);
        let gradients = Gradients::new(&domain);
        let laplacians = (0..domain.len())
            .map(|k| laplacian(&domain, k, authors_quirks))
            .collect();
        let intensities = (0..domain.len())
            .flat_map(|k| {
                let (x, y) = domain.pixel(k);
                obs.images.iter().map(move |im| *im.get(x * step, y * step))
            })
            .collect();
        let specular = (0..domain.len())
            .map(|k| {
                let (x, y) = domain.pixel(k);
                *obs.specular.get(x * step, y * step)
            })
            .collect();
        let targets = layers(&mask, authors_quirks)
            .into_iter()
            .map(|l| Target {
                unknown: domain.unknown(l.pixel).expect("layers lie in the mask"),
                azimuth: l.azimuth,
                weight: l.weight,
            })
            .collect();
        Some(Level {
            step,
            domain,
            gradients,
            laplacians,
            intensities,
            angles: obs.angles.clone(),
            specular,
            targets,
            eta,
            authors_quirks,
        })
    }

    /// How unknown `k` reflects in the ratio stage.
    pub fn reflection(&self, k: usize) -> Reflection {
        match (self.specular[k], self.authors_quirks) {
            (false, _) => Reflection::Diffuse,
            (true, false) => Reflection::Specular,
            (true, true) => Reflection::SpecularUnturned,
        }
    }

    /// Number of polarizer angles.
    pub fn angle_count(&self) -> usize {
        self.angles.len()
    }
}

#[cfg(test)]
pub mod tests {
    use super::*;
    use crate::methods::yu2017::model::Pixel;

    /// A 16² view of a sphere cap (heights `√(64 − r²)`, lit by `light`,
    /// albedo 0.8, four polarizer angles, some pixels specular), its
    /// level at full resolution and the true heights.
    pub fn sphere(light: [f64; 3]) -> (Level, Vec<f64>) {
        let n = 16;
        let height = |x: f64, y: f64| (64.0 - (x - 7.5).powi(2) - (y - 7.5).powi(2)).sqrt();
        let mask = Mask::from_fn(n, n, |x, y| height(x as f64, y as f64) > 2.5);
        let angles: Vec<f64> = [0.0f64, 45.0, 90.0, 135.0].iter().map(|a| a.to_radians()).collect();
        let images = angles
            .iter()
            .map(|&t| {
                Image::from_fn(n, n, |x, y| {
                    let (x, y) = (x as f64, y as f64);
                    // y up: a row down is −y.
                    let (p, q) = (
                        (height(x + 1e-4, y) - height(x - 1e-4, y)) / 2e-4,
                        -(height(x, y + 1e-4) - height(x, y - 1e-4)) / 2e-4,
                    );
                    let g = (1.0 + p * p + q * q).sqrt();
                    let shade = (light[2] - p * light[0] - q * light[1]) / g;
                    let pixel = Pixel::of(p, q, 1.5, super::Reflection::Diffuse);
                    30000.0 * (0.8 * shade).max(0.0) * pixel.transmitted(t).0
                })
            })
            .collect();
        let obs = Observations {
            angles,
            images,
            specular: Mask::from_fn(n, n, |x, y| (x + y) % 7 == 0),
            mask,
        };
        let level = Level::new(&obs, 1, 1.5, false).unwrap();
        let z = (0..level.domain.len())
            .map(|k| {
                let (x, y) = level.domain.pixel(k);
                height(x as f64, y as f64)
            })
            .collect();
        (level, z)
    }
}
