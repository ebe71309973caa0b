//! Exact, noise-free views of analytic shapes: the oracle every method and the
//! renderer are tested against. Not a renderer: shading is the Lambertian
//! model the reconstruction methods assume, `I_un = albedo · max(0, n·l)`,
//! the DoP is `ρ_d(θ, η)` (conventions.md §3) and the AoP is the normal's
//! azimuth modulo π.
//!
//! Geometry is in pixel units under an orthographic camera looking along `−z`:
//! pixel `(col, row)` has centre `x = col + ½ − w/2`, `y = h/2 − row − ½`
//! (y up, conventions.md §1). Depth is measured from a camera plane at
//! `z = size`.

use crate::fresnel::diffuse_dop;
use crate::stokes::{STANDARD_ANGLES, Stokes, wrap_aop};
use crate::view::{GroundTruth, Meta, View, ViewInput};
use crate::{Error, Image, Result};
use serde::{Deserialize, Serialize};

/// The analytic surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    /// A sphere of radius `0.45 · size` centred in the image: convex, with an
    /// occluding contour all round.
    Sphere,
    /// Gaussian bumps and one dimple over a disc of radius `0.45 · size`:
    /// locally convex lobes meeting in concave creases; the disc's rim is a
    /// crease of the height field, not an occluding contour.
    Blobs,
}

/// Settings of an analytic view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnalyticScene {
    pub shape: Shape,
    /// Image width and height in pixels.
    pub size: usize,
    pub eta: f64,
    pub albedo: f64,
    /// Direction towards the light (camera frame); its length is the irradiance.
    pub light: [f64; 3],
}

impl Default for AnalyticScene {
    fn default() -> Self {
        AnalyticScene {
            shape: Shape::Sphere,
            size: 128,
            eta: 1.5,
            albedo: 0.8,
            light: [0.0, 0.0, 1.0],
        }
    }
}

/// One Gaussian term `a · exp(−|p − c|² / 2σ²)` of the blobs height field, in
/// units of the image size.
const BLOBS: [(f64, f64, f64, f64); 6] = [
    // (cx, cy, sigma, amplitude)
    (0.0, 0.0, 0.10, 0.16),
    (0.20, 0.12, 0.08, 0.12),
    (-0.18, 0.16, 0.09, 0.13),
    (-0.12, -0.20, 0.07, 0.10),
    (0.17, -0.17, 0.08, 0.11),
    (0.0, 0.24, 0.05, -0.05),
];

/// Surface sample at a pixel centre: height and unit normal.
fn surface(shape: Shape, size: f64, x: f64, y: f64) -> Option<(f64, [f64; 3])> {
    let r = 0.45 * size;
    let r2 = x * x + y * y;
    if r2 >= r * r {
        return None;
    }
    match shape {
        Shape::Sphere => {
            let z = (r * r - r2).sqrt();
            Some((z, [x / r, y / r, z / r]))
        }
        Shape::Blobs => {
            let (mut z, mut zx, mut zy) = (0.0, 0.0, 0.0);
            for (cx, cy, s, a) in BLOBS {
                let (dx, dy, s) = (x - cx * size, y - cy * size, s * size);
                let g = a * size * (-(dx * dx + dy * dy) / (2.0 * s * s)).exp();
                z += g;
                zx -= g * dx / (s * s);
                zy -= g * dy / (s * s);
            }
            let k = 1.0 / (1.0 + zx * zx + zy * zy).sqrt();
            Some((z, [-zx * k, -zy * k, k]))
        }
    }
}

impl AnalyticScene {
    /// Renders the view: 16-bit polarizer images, mask, exact ground truth.
    pub fn render(&self) -> Result<View> {
        if self.size < 4 || self.size > 16384 {
            return Err(Error::invalid(format!(
                "size {} must be within 4..=16384",
                self.size
            )));
        }
        crate::fresnel::check_eta(self.eta, crate::fresnel::MATERIAL_ETA_MAX)?;
        if !(self.albedo > 0.0 && self.albedo.is_finite()) {
            return Err(Error::invalid(format!(
                "albedo {} must be > 0",
                self.albedo
            )));
        }
        let l = self.light;
        let irradiance = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        if !(irradiance > 0.0 && irradiance.is_finite()) {
            return Err(Error::invalid("light must be a finite non-zero vector"));
        }
        let n = self.size;
        let half = n as f64 / 2.0;
        let mut normals = Image::new(n, n, [0.0f32; 3]);
        let mut depth = Image::new(n, n, f32::NAN);
        let mut albedo = Image::new(n, n, 0.0f32);
        let mut stokes = [(); 3].map(|_| Image::new(n, n, 0.0f32));
        let mut mask = Image::new(n, n, false);
        let mut exact = vec![Stokes::default(); n * n];
        for row in 0..n {
            for col in 0..n {
                let x = col as f64 + 0.5 - half;
                let y = half - row as f64 - 0.5;
                let Some((z, nv)) = surface(self.shape, n as f64, x, y) else {
                    continue;
                };
                let i = mask.index(col, row);
                mask.data_mut()[i] = true;
                normals.data_mut()[i] = nv.map(|v| v as f32);
                depth.data_mut()[i] = (n as f64 - z) as f32;
                albedo.data_mut()[i] = self.albedo as f32;
                let shading = (nv[0] * l[0] + nv[1] * l[1] + nv[2] * l[2]).max(0.0);
                let s0 = 2.0 * self.albedo * shading;
                let theta = nv[2].clamp(-1.0, 1.0).acos();
                let aop = wrap_aop(nv[1].atan2(nv[0]));
                let s = Stokes::from_polarization(s0, diffuse_dop(theta, self.eta), aop);
                exact[i] = s;
                stokes[0].data_mut()[i] = s.s0 as f32;
                stokes[1].data_mut()[i] = s.s1 as f32;
                stokes[2].data_mut()[i] = s.s2 as f32;
            }
        }
        // Radiance 1 maps to full scale unless that would clip; the gain is
        // folded into `meta.light` so that I_un = albedo · n·light holds in
        // full-scale units of the stored images.
        let peak = exact
            .iter()
            .flat_map(|s| STANDARD_ANGLES.map(|a| s.through_polarizer(a)))
            .fold(0.0f64, f64::max);
        let gain = if peak > 0.95 { 0.95 / peak } else { 1.0 };
        let full = f64::from(u16::MAX);
        let pol = STANDARD_ANGLES.map(|a| {
            Image::from_vec(
                n,
                n,
                exact
                    .iter()
                    .map(|s| {
                        (s.through_polarizer(a) * gain * full)
                            .round()
                            .clamp(0.0, full) as u16
                    })
                    .collect(),
            )
            .expect("size matches")
        });
        let mut meta = Meta::new("sfp analytic");
        meta.eta = Some(self.eta);
        meta.albedo = Some(self.albedo);
        meta.light = Some(l.map(|v| v * gain));
        meta.extra.insert(
            "analytic".into(),
            serde_json::to_value(self).expect("settings serialise"),
        );
        meta.extra.insert("gain".into(), gain.into());
        Ok(View {
            input: ViewInput::grey(pol, 16, Some(mask)),
            gt: Some(GroundTruth {
                normals,
                depth: Some(depth),
                stokes: Some(stokes),
                channel_stokes: None,
                albedo: Some(albedo),
                geometric_normals: None,
                specular: None,
                specular_stokes: None,
            }),
            meta: Some(meta),
            problems: Vec::new(),
            source: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::diffuse_dop;
    use std::f64::consts::PI;

    fn axial_diff(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(PI);
        d.min(PI - d)
    }

    /// AoP equals the GT azimuth mod π and DoP equals ρ_d(θ_gt, η) at every
    /// lit pixel: exactly (f32) from gt/stokes, within quantization from the
    /// 16-bit polarizer images.
    fn check_polarization(shape: Shape) {
        let scene = AnalyticScene {
            shape,
            size: 96,
            light: [0.3, -0.2, 1.0],
            ..AnalyticScene::default()
        };
        let view = scene.render().unwrap();
        let gt = view.gt.as_ref().unwrap();
        let pm = view.input.polarimetry();
        let exact = crate::stokes::Polarimetry::from_stokes(gt.stokes.as_ref().unwrap());
        let mask = view.input.mask.as_ref().unwrap();
        let mut checked = 0;
        for i in 0..mask.len() {
            if !mask.data()[i] || gt.stokes.as_ref().unwrap()[0].data()[i] <= 0.0 {
                continue;
            }
            let n = gt.normals.data()[i].map(f64::from);
            let theta = n[2].acos();
            let phi = n[1].atan2(n[0]);
            let rho = diffuse_dop(theta, scene.eta);
            assert!((f64::from(exact.dop.data()[i]) - rho).abs() < 1e-5);
            if rho > 1e-3 {
                assert!(axial_diff(f64::from(exact.aop.data()[i]), phi) < 1e-3);
            }
            // Quantization error of a code is ≤ ½ LSB on each of four images.
            let s0 = f64::from(pm.intensity.data()[i]) * 2.0;
            let tol = 4.0 / 65535.0 / s0;
            assert!(
                (f64::from(pm.dop.data()[i]) - rho).abs() < tol + 1e-6,
                "dop {} vs {rho} (tol {tol})",
                pm.dop.data()[i]
            );
            if rho > 0.02 {
                assert!(axial_diff(f64::from(pm.aop.data()[i]), phi) < 2.0 * tol / rho + 1e-5);
            }
            checked += 1;
        }
        assert!(
            checked > mask.count() / 2,
            "only {checked} lit pixels checked"
        );
    }

    #[test]
    fn sphere_polarization_matches_model() {
        check_polarization(Shape::Sphere);
    }

    #[test]
    fn blobs_polarization_matches_model() {
        check_polarization(Shape::Blobs);
    }

    #[test]
    fn sphere_normals_are_unit_and_face_the_camera() {
        let view = AnalyticScene::default().render().unwrap();
        let gt = view.gt.unwrap();
        let mask = view.input.mask.unwrap();
        for (n, &m) in gt.normals.data().iter().zip(mask.data()) {
            if m {
                let len = n.iter().map(|v| v * v).sum::<f32>().sqrt();
                assert!((len - 1.0).abs() < 1e-6 && n[2] > 0.0);
            } else {
                assert_eq!(*n, [0.0; 3]);
            }
        }
    }

    #[test]
    fn shading_is_lambertian_in_full_scale_units() {
        let scene = AnalyticScene {
            light: [0.5, 0.5, 0.9],
            ..AnalyticScene::default()
        };
        let view = scene.render().unwrap();
        let meta = view.meta.as_ref().unwrap();
        let l = meta.light.unwrap();
        let pm = view.input.polarimetry();
        let gt = view.gt.as_ref().unwrap();
        for (i, n) in gt.normals.data().iter().enumerate() {
            let n = n.map(f64::from);
            let expected = scene.albedo * (n[0] * l[0] + n[1] * l[1] + n[2] * l[2]).max(0.0);
            assert!((f64::from(pm.intensity.data()[i]) - expected).abs() < 3e-5);
        }
    }

    #[test]
    fn bad_settings_are_errors() {
        for scene in [
            AnalyticScene {
                size: 0,
                ..AnalyticScene::default()
            },
            AnalyticScene {
                eta: 0.9,
                ..AnalyticScene::default()
            },
            AnalyticScene {
                light: [0.0; 3],
                ..AnalyticScene::default()
            },
            AnalyticScene {
                light: [f64::NAN, 0.0, 1.0],
                ..AnalyticScene::default()
            },
        ] {
            assert!(scene.render().is_err());
        }
    }
}
