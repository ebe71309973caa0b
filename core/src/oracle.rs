//! The per-pixel oracles of a view with ground truth: the best a method
//! could score that reads each pixel's DoP and AoP alone under a
//! reflection model, were the ground truth to pick among the normals the
//! model allows, at the view's true η. What no per-pixel method can beat,
//! and what a surface fit (which ties pixels together) can.
//!
//! - **diffuse**: the zenith `ρ_d⁻¹(ρ)` (conventions.md §3, clamped at the
//!   diffuse ceiling) at azimuths `ψ` and `ψ + π`;
//! - **mixed**: those two, and both specular zeniths `ρ_s⁻¹(ρ)` (below and
//!   above Brewster's angle) at azimuths `ψ ± π/2`, the specular AoP being
//!   perpendicular to the plane of incidence: six candidates.
//!
//! Scored as every method is (§4): angular error over the mask, in degrees.

use crate::fresnel::{
    diffuse_zenith, specular_zenith_above_brewster, specular_zenith_below_brewster,
};
use crate::metrics::{Metrics, summarize};
use crate::view::View;
use crate::{Error, Image, Mask, NormalMap, Result};
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, PI};

/// Both oracles' figures and the η they used.
#[derive(Clone, Debug, Serialize)]
pub struct Oracles {
    pub eta: f64,
    pub diffuse: Metrics,
    pub mixed: Metrics,
}

/// Which oracle: the reflection model whose normals it picks among.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OracleModel {
    Diffuse,
    Mixed,
}

impl OracleModel {
    pub const ALL: [OracleModel; 2] = [OracleModel::Diffuse, OracleModel::Mixed];

    pub fn name(self) -> &'static str {
        match self {
            OracleModel::Diffuse => "diffuse",
            OracleModel::Mixed => "mixed",
        }
    }
}

impl Oracles {
    /// The figures of the oracle of `model`.
    pub fn of(&self, model: OracleModel) -> &Metrics {
        match model {
            OracleModel::Diffuse => &self.diffuse,
            OracleModel::Mixed => &self.mixed,
        }
    }
}

/// The oracles of `view` at η `eta`; `None` without ground truth.
pub fn oracles(view: &View, eta: f64) -> Option<Result<Oracles>> {
    let gt = view.gt.as_ref()?;
    let pm = view.input.polarimetry();
    let mask = view.scored_mask()?;
    Some(oracles_of(&pm.dop, &pm.aop, &gt.normals, &mask, eta))
}

/// The oracles of the DoP `dop` and AoP `aop` against the normals `truth`
/// over `mask`, at η `eta` (a sweep's exposures, whose polarimetry is not a
/// stored view's).
pub fn oracles_of(
    dop: &Image<f32>,
    aop: &Image<f32>,
    truth: &NormalMap,
    mask: &Mask,
    eta: f64,
) -> Result<Oracles> {
    if !dop.same_size(mask) || !aop.same_size(mask) || !truth.same_size(mask) {
        return Err(Error::invalid(
            "the oracles' DoP, AoP, normals and mask differ in size",
        ));
    }
    let (mut diffuse, mut mixed) = (Vec::new(), Vec::new());
    for i in (0..mask.len()).filter(|&i| mask.data()[i]) {
        let truth = truth.data()[i].map(f64::from);
        let rho = f64::from(dop.data()[i]);
        let psi = f64::from(aop.data()[i]);
        let error = |theta: f64, phi: f64| angle_deg(normal(theta, phi), truth);
        let theta_d = diffuse_zenith(rho, eta);
        let d = error(theta_d, psi).min(error(theta_d, psi + PI));
        let s = [
            specular_zenith_below_brewster(rho, eta),
            specular_zenith_above_brewster(rho, eta),
        ]
        .into_iter()
        .flat_map(|theta| [psi + FRAC_PI_2, psi - FRAC_PI_2].map(|phi| error(theta, phi)))
        .fold(f64::INFINITY, f64::min);
        diffuse.push(d);
        mixed.push(d.min(s));
    }
    Ok(Oracles {
        eta,
        diffuse: summarize(&mut diffuse, 0)?,
        mixed: summarize(&mut mixed, 0)?,
    })
}

/// The unit normal of zenith `theta` and azimuth `phi` (conventions.md §1).
fn normal(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    let c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / nb.max(f64::MIN_POSITIVE);
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::{diffuse_dop, specular_dop};
    use crate::image::Image;
    use crate::view::{GroundTruth, ViewInput};

    /// Noise-free pixels of each model (codes of a 16-bit sensor): the
    /// mixed oracle recovers both; the diffuse one misreads the specular one.
    #[test]
    fn each_oracle_recovers_the_pixels_of_its_model() {
        let eta = 1.5;
        let (theta_d, phi_d) = (50f64.to_radians(), 0.3);
        let (theta_s, phi_s) = (70f64.to_radians(), 2.0);
        // A diffuse pixel's AoP lies along the azimuth, a specular one's across it.
        let pixels = [
            (normal(theta_d, phi_d), diffuse_dop(theta_d, eta), phi_d),
            (
                normal(theta_s, phi_s),
                specular_dop(theta_s, eta),
                phi_s + FRAC_PI_2,
            ),
        ];
        let pol = [0.0f64, 45.0, 90.0, 135.0].map(|deg| {
            let a = deg.to_radians();
            let codes = pixels
                .iter()
                .map(|&(_, rho, psi)| {
                    (30000.0 * (1.0 + rho * (2.0 * (a - psi)).cos())).round() as u16
                })
                .collect();
            Image::from_vec(2, 1, codes).unwrap()
        });
        let normals = pixels.iter().map(|p| p.0.map(|v| v as f32)).collect();
        let mut view = View {
            input: ViewInput::grey(pol, 16, None),
            gt: Some(GroundTruth::of_normals(
                Image::from_vec(2, 1, normals).unwrap(),
            )),
            meta: None,
            problems: Vec::new(),
            source: None,
        };
        let o = oracles(&view, eta).unwrap().unwrap();
        assert!(o.mixed.mae_deg < 0.1, "{:?}", o.mixed);
        assert!(o.diffuse.mae_deg > 5.0, "{:?}", o.diffuse);
        view.gt = None;
        assert!(oracles(&view, eta).is_none());
    }
}
