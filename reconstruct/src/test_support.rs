//! Fixtures the tests share: analytic views and the error
//! of a method on them.

use crate::input::Input;
use crate::method::{Method, Reconstruction};
use sfp_core::Image;
use sfp_core::NormalMap;
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::fresnel::{diffuse_dop, reflectance, specular_dop};
use sfp_core::metrics::evaluate;
use sfp_core::stokes::Polarimetry;
use std::f64::consts::{FRAC_PI_2, PI};

/// A mask drawn as text rows, `#` inside.
pub(crate) fn mask_of(rows: &[&str]) -> sfp_core::Mask {
    sfp_core::Mask::from_fn(rows[0].len(), rows.len(), |x, y| {
        rows[y].as_bytes()[x] == b'#'
    })
}

/// The analytic views' light.
pub(crate) const LIGHT: [f64; 3] = [0.35, 0.25, 0.9];

/// An analytic `shape` of `size²` pixels and refractive index `eta` under
/// [`LIGHT`]: its input and its true normals.
pub(crate) fn analytic(shape: Shape, size: usize, eta: f64) -> (Input, NormalMap) {
    let view = AnalyticScene {
        shape,
        size,
        eta,
        albedo: 0.8,
        light: LIGHT,
    }
    .render()
    .unwrap();
    let input = Input::from_view(&view.input).unwrap();
    (input, view.gt.unwrap().normals)
}

/// `method`'s mean angular error (degrees) on `input` against `gt`, and its
/// reconstruction; every mask pixel must have a normal.
pub(crate) fn mae(method: &dyn Method, input: &Input, gt: &NormalMap) -> (f64, Reconstruction) {
    let rec = method.reconstruct(input).unwrap();
    let m = evaluate(&rec.normals, gt, &input.mask).unwrap();
    assert_eq!(m.missing, 0);
    (m.mae_deg, rec)
}

/// The analytic sphere of `size²` pixels: its diffuse light plus the specular reflection of
/// surroundings of radiance `surroundings` (in units of the robust
/// maximum intensity), with the polarization this mixture has; and the
/// surroundings' radiance in intensity units.
pub(crate) fn glossy_sphere(size: usize, surroundings: f64) -> (Input, f32) {
    let (input, gt) = analytic(Shape::Sphere, size, 1.5);
    let l = surroundings * input.intensity_scale;
    let (w, h) = input.size();
    let mut intensity = Image::new(w, h, 0.0f32);
    let mut dop = Image::new(w, h, 0.0f32);
    let mut aop = Image::new(w, h, 0.0f32);
    for i in 0..input.mask.len() {
        if !input.mask.data()[i] {
            continue;
        }
        let n = gt.data()[i];
        let theta = f64::from(n[2]).clamp(-1.0, 1.0).acos();
        let (rs, rp) = reflectance(theta.cos(), 1.5);
        let diffuse = f64::from(input.intensity.data()[i]);
        let s = diffuse + l * (rs + rp) / 2.0;
        let q = diffuse * diffuse_dop(theta, 1.5) - l * (rs - rp) / 2.0;
        intensity.data_mut()[i] = s as f32;
        dop.data_mut()[i] = (q.abs() / s) as f32;
        let turned = if q < 0.0 { FRAC_PI_2 } else { 0.0 };
        aop.data_mut()[i] = (f64::from(input.aop.data()[i]) + turned).rem_euclid(PI) as f32;
    }
    let pol = Polarimetry {
        intensity,
        dop,
        aop,
    };
    (Input::new(pol, Some(input.mask.clone())).unwrap(), l as f32)
}

/// The analytic sphere at `eta` (64²) with each mask pixel's polarization
/// replaced by that of a mixture with specular share `share(x)`:
/// `(1 − f) ρ_d − f ρ_s` along the azimuth (AoP turned by 90° where it
/// is negative). Returns the input and the true normals.
pub(crate) fn mixture(eta: f64, share: impl Fn(usize) -> f64) -> (Input, NormalMap) {
    let (mut input, normals) = analytic(Shape::Sphere, 64, eta);
    let (w, h) = input.size();
    for y in 0..h {
        for x in 0..w {
            if !*input.mask.get(x, y) {
                continue;
            }
            let [nx, ny, nz] = normals.get(x, y).map(f64::from);
            let (theta, f) = (nz.clamp(-1.0, 1.0).acos(), share(x));
            let q = (1.0 - f) * diffuse_dop(theta, eta) - f * specular_dop(theta, eta);
            let phi = ny.atan2(nx) + if q < 0.0 { FRAC_PI_2 } else { 0.0 };
            *input.dop.get_mut(x, y) = q.abs() as f32;
            *input.aop.get_mut(x, y) = phi.rem_euclid(PI) as f32;
        }
    }
    (input, normals)
}

/// `input` where pixel `(x, y)` with `at(x, y)` also carries a reflected
/// compact light's polarization: `strength` of `s0` at AoP `aop`, whatever
/// the normal there (rough microfacets facing the light).
pub(crate) fn with_reflected_light(
    mut input: Input,
    strength: f64,
    aop: f64,
    at: impl Fn(usize, usize) -> bool,
) -> Input {
    let (w, h) = input.size();
    for y in 0..h {
        for x in 0..w {
            if !at(x, y) {
                continue;
            }
            let (rho, psi) = (
                f64::from(*input.dop.get(x, y)),
                f64::from(*input.aop.get(x, y)),
            );
            let v = [
                rho * (2.0 * psi).cos() + strength * (2.0 * aop).cos(),
                rho * (2.0 * psi).sin() + strength * (2.0 * aop).sin(),
            ];
            *input.dop.get_mut(x, y) = v[0].hypot(v[1]) as f32;
            *input.aop.get_mut(x, y) = (0.5 * v[1].atan2(v[0])).rem_euclid(PI) as f32;
        }
    }
    input
}
