//! Shared helpers of the renderer's integration tests: independent closed
//! forms (f64, from `sfp_core::fresnel` only) and scene text.

#![allow(dead_code)] // each test binary uses a different subset

use sfp_core::fresnel::{diffuse_dop, transmittance};
use sfp_renderer::scene::Scene;
use std::f64::consts::PI;
use std::path::Path;

pub const EXAMPLE: &str = include_str!("../../../scenes/examples/sphere.toml");

pub fn parse(text: &str) -> Scene {
    Scene::from_toml(text, Path::new("/tmp/test-scene.toml")).expect("scene parses")
}

/// The scene with every `diffuse_polarized` material turned into the
/// equivalent `svbrdf` one with constant maps (the keys are the same).
pub fn as_svbrdf(text: &str) -> String {
    text.replace("\"diffuse_polarized\"", "\"svbrdf\"")
}

/// `(T_s + T_p)/2`.
pub fn t_avg(cos: f64, eta: f64) -> f64 {
    let (ts, tp) = transmittance(cos, eta);
    0.5 * (ts + tp)
}

/// Closed-form single scattering off the unit sphere at the origin, seen by an
/// orthographic camera along −z whose image x axis is rotated by `roll` (rad)
/// about the view axis; `(xc, yc)` are camera-plane coordinates. Returns
/// `(s0, s1, s2)` in the camera frame, or `None` off the sphere.
pub fn single_scatter(
    xc: f64,
    yc: f64,
    roll: f64,
    light: [f64; 3],
    irradiance: f64,
    albedo: f64,
    eta: f64,
) -> Option<[f64; 3]> {
    let r2 = xc * xc + yc * yc;
    if r2 >= 1.0 {
        return None;
    }
    let (c, s) = (roll.cos(), roll.sin());
    // World coordinates of the camera-plane point.
    let (xw, yw) = (c * xc - s * yc, s * xc + c * yc);
    let n = [xw, yw, (1.0 - r2).sqrt()];
    let norm = (light[0].powi(2) + light[1].powi(2) + light[2].powi(2)).sqrt();
    let cos_i = (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / norm;
    if cos_i <= 0.0 {
        return Some([0.0; 3]);
    }
    let s0 = albedo / PI * irradiance * cos_i * t_avg(cos_i, eta) * t_avg(n[2], eta);
    let dop = diffuse_dop(n[2].acos(), eta);
    // AoP ∥ normal azimuth, measured in the rolled camera frame.
    let aop = n[1].atan2(n[0]) - roll;
    Some([
        s0,
        s0 * dop * (2.0 * aop).cos(),
        s0 * dop * (2.0 * aop).sin(),
    ])
}

/// Camera-plane coordinates of position `(px, py)` (in pixels) of an
/// orthographic `w × h` image spanning `extent` in x.
pub fn plane_coords(px: f64, py: f64, w: usize, h: usize, extent: f64) -> (f64, f64) {
    let hw = 0.5 * extent;
    let hh = hw * h as f64 / w as f64;
    (
        (2.0 * px / w as f64 - 1.0) * hw,
        (1.0 - 2.0 * py / h as f64) * hh,
    )
}

/// Writes a UV sphere (radius 1, `rings × segments` quads split into
/// triangles, exact vertex normals) as OBJ.
pub fn write_uv_sphere(path: &Path, rings: usize, segments: usize) {
    use std::fmt::Write;
    let mut s = String::new();
    for i in 0..=rings {
        let th = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let ph = 2.0 * PI * j as f64 / segments as f64;
            let (x, y, z) = (th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            writeln!(s, "v {x} {y} {z}\nvn {x} {y} {z}").unwrap();
        }
    }
    let idx = |i: usize, j: usize| i * segments + (j % segments) + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            if i != 0 {
                writeln!(s, "f {a}//{a} {b}//{b} {d}//{d}").unwrap();
            }
            if i != rings - 1 {
                writeln!(s, "f {b}//{b} {c}//{c} {d}//{d}").unwrap();
            }
        }
    }
    std::fs::write(path, s).unwrap();
}
