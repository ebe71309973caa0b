//! A numeric summary of a view's input, for `sfp inspect`: what a user checks
//! first when a capture or a rendered view looks wrong.

use crate::fresnel::diffuse_dop_max;
use crate::oracle::{Oracles, oracles};
use crate::percentile::percentile;
use crate::view::View;
use serde::Serialize;

/// Robust statistics of one quantity over the mask.
#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    pub min: f32,
    pub median: f32,
    pub p99: f32,
    pub max: f32,
    pub mean: f32,
}

impl Stats {
    fn of(values: &[f32]) -> Stats {
        let n = values.len().max(1) as f32;
        Stats {
            min: values.iter().copied().fold(f32::INFINITY, f32::min),
            median: percentile(values, 0.5),
            p99: percentile(values, 0.99),
            max: values.iter().copied().fold(f32::NEG_INFINITY, f32::max),
            mean: values.iter().sum::<f32>() / n,
        }
    }
}

/// Summary printed by `sfp inspect`.
#[derive(Clone, Debug, Serialize)]
pub struct InputSummary {
    pub width: usize,
    pub height: usize,
    pub bits: u8,
    /// Pixels inside the mask (all pixels when there is no mask).
    pub pixels: usize,
    pub has_mask: bool,
    pub has_ground_truth: bool,
    /// Unpolarized intensity in units of the sensor's full scale.
    pub intensity: Stats,
    /// Fraction of all the image's pixels with a polarizer image at full
    /// scale (clipped): counted over the whole frame, since an import leaves
    /// saturated pixels out of the mask (counted inside it, it was always 0).
    pub saturated_fraction: f64,
    pub dop: Stats,
    /// Refractive index used for the model check below (meta.json or 1.5).
    pub eta: f64,
    /// Fraction of pixels whose DoP exceeds the diffuse model's maximum at `eta`
    /// (specular reflection, noise, or a wrong η).
    pub dop_above_diffuse_max: f64,
    /// Circular mean of the AoP (axial, degrees in [0, 180)) and its resultant
    /// length (0 = uniformly spread, 1 = one angle everywhere).
    pub aop_mean_deg: f64,
    pub aop_concentration: f64,
    /// With ground truth: the best per-pixel readings under the diffuse and
    /// the mixed model at `eta` (`oracle`), the bounds of per-pixel methods.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oracles: Option<Oracles>,
}

/// Summarises `view`'s input over its mask.
pub fn summarize(view: &View) -> InputSummary {
    let input = &view.input;
    let pm = input.polarimetry();
    let (w, h) = input.size();
    let inside: Vec<usize> = (0..w * h)
        .filter(|&i| input.mask.as_ref().is_none_or(|m| m.data()[i]))
        .collect();
    let pick = |img: &crate::Image<f32>| inside.iter().map(|&i| img.data()[i]).collect::<Vec<_>>();
    let eta = view.meta.as_ref().and_then(|m| m.eta).unwrap_or(1.5);
    let dop = pick(&pm.dop);
    let max_dop = diffuse_dop_max(eta) as f32;
    let saturated = input.saturated().count();
    let (mut c, mut s) = (0.0f64, 0.0f64);
    for &i in &inside {
        let a = 2.0 * f64::from(pm.aop.data()[i]);
        c += a.cos();
        s += a.sin();
    }
    let n = inside.len().max(1) as f64;
    InputSummary {
        width: w,
        height: h,
        bits: input.bits,
        pixels: inside.len(),
        has_mask: input.mask.is_some(),
        has_ground_truth: view.gt.is_some(),
        intensity: Stats::of(&pick(&pm.intensity)),
        saturated_fraction: saturated as f64 / (w * h).max(1) as f64,
        dop: Stats::of(&dop),
        eta,
        dop_above_diffuse_max: dop.iter().filter(|&&d| d > max_dop).count() as f64 / n,
        aop_mean_deg: (0.5 * s.atan2(c)).to_degrees().rem_euclid(180.0),
        aop_concentration: c.hypot(s) / n,
        oracles: oracles(view, eta).and_then(Result::ok),
    }
}
