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
    /// mask is empty); `authors_quirks` keeps their specular phase (Q1) and
    /// Laplacian (Q3).
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
        let targets = layers(&mask)
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
