//! Normal maps against closed forms: a flat quad facing an orthographic camera
//! and a light along the view axis, single scattering, no jitter, so every
//! pixel centre is exactly the Fresnel-weighted Lambert term of its mapped
//! normal `n'`: `s0 = albedo/π · E · cosθ · T(θ)²`, DoP `ρ_d(θ, η)`, AoP the
//! azimuth of `n'` (mod π), with `cosθ = n'_z`.

mod common;

use common::{plane_coords, t_avg};
use sfp_core::fresnel::diffuse_dop;
use sfp_renderer::render::{RenderOptions, render};
use sfp_renderer::scene::Scene;
use std::f64::consts::{PI, TAU};
use std::path::Path;

const SIZE: usize = 64;

fn scene(material: &str, mesh: &str) -> String {
    format!(
        r#"
[camera]
type = "orthographic"
width = {SIZE}
height = {SIZE}
extent = 2.0
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]

[render]
spp = 1
max_depth = 1
jitter = false

[[light]]
type = "directional"
direction = [0.0, 0.0, 1.0]
irradiance = 3.0

[[object]]
mesh = "{mesh}"
rotate = [0.0, 0.0, 30.0]
material = {material}

[sensor]
noise = false
"#
    )
}

/// Checks every pixel against the closed form of `normal(x, y)` (camera =
/// world frame); returns how many pixels had a measurable AoP.
fn check(dir: &Path, text: &str, normal: impl Fn(f64, f64) -> [f64; 3]) -> usize {
    let scene = Scene::from_toml(text, &dir.join("scene.toml")).unwrap();
    let out = render(&scene, &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let stokes = gt.stokes.as_ref().unwrap();
    let geometric = gt.geometric_normals.as_ref().unwrap();
    let (eta, albedo) = (1.5, 0.8);
    let mut with_aop = 0;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, SIZE, SIZE, 2.0);
            let n = normal(xc, yc);
            let got_n = gt.normals.get(x, y).map(f64::from);
            for k in 0..3 {
                assert!(
                    (got_n[k] - n[k]).abs() < 2e-4,
                    "({x}, {y}): {got_n:?} vs {n:?}"
                );
            }
            let g = geometric.get(x, y);
            assert!(g[0].abs() < 1e-6 && g[1].abs() < 1e-6 && (g[2] - 1.0).abs() < 1e-6);
            let s = [0, 1, 2].map(|k| f64::from(*stokes[k].get(x, y)));
            let cos = n[2];
            let s0 = albedo / PI * 3.0 * cos * t_avg(cos, eta).powi(2);
            assert!(
                (s[0] / s0 - 1.0).abs() < 2e-4,
                "({x}, {y}): s0 {} vs {s0}",
                s[0]
            );
            let dop = s[1].hypot(s[2]) / s[0];
            let want = diffuse_dop(cos.acos(), eta);
            assert!((dop - want).abs() < 1e-4, "({x}, {y}): DoP {dop} vs {want}");
            if want > 1e-3 {
                with_aop += 1;
                let aop = 0.5 * s[2].atan2(s[1]);
                let azimuth = n[1].atan2(n[0]);
                // Difference mod π, folded into [−π/2, π/2).
                let d = (aop - azimuth + 2.5 * PI).rem_euclid(PI) - 0.5 * PI;
                assert!(d.abs() < 0.2f64.to_radians(), "({x}, {y}): AoP off by {d}");
            }
        }
    }
    with_aop
}

/// The height field `A (½ + ½ sin 2πf x')` along the quad's own `x'` axis
/// (turned 30° in the image): `n' ∝ (−A π f cos(2πf x') d, 1)`, `d` = the
/// turned `x` axis.
#[test]
fn sinusoidal_bump_map_matches_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let (a, f) = (0.1, 2.0);
    let material = format!(
        r#"{{ type = "svbrdf", eta = 1.5, albedo = 0.8, normal = {{ pattern = "stripes", frequency = {f}, amplitude = {a} }} }}"#
    );
    let d = [30f64.to_radians().cos(), 30f64.to_radians().sin()];
    let lit = check(dir.path(), &scene(&material, "quad.obj"), |x, y| {
        let slope = a * PI * f * (TAU * f * (x * d[0] + y * d[1])).cos();
        let n = [-slope * d[0], -slope * d[1], 1.0];
        let len = (n[0] * n[0] + n[1] * n[1] + 1.0).sqrt();
        n.map(|c| c / len)
    });
    assert!(lit > SIZE * SIZE / 2, "{lit} pixels with an AoP");
}

/// A constant tangent-space normal texture `(0.6, 0, 0.8)` on a quad whose
/// `u` runs along its own `x'` axis: `n' = 0.6 d + 0.8 z`.
#[test]
fn tangent_space_normal_texture_follows_uv_frame() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    // Linear EXR texels: (R, G, B) = (n' + 1)/2.
    let c = |v: f32| sfp_core::Image::new(2, 2, 0.5 * (v + 1.0));
    sfp_core::io::write_exr(
        &dir.path().join("n.exr"),
        &[("R", &c(0.6)), ("G", &c(0.0)), ("B", &c(0.8))],
    )
    .unwrap();
    let material =
        r#"{ type = "svbrdf", eta = 1.5, albedo = 0.8, normal = { texture = "n.exr" } }"#;
    let d = [30f64.to_radians().cos(), 30f64.to_radians().sin()];
    let lit = check(dir.path(), &scene(material, "quad.obj"), |_, _| {
        [0.6 * d[0], 0.6 * d[1], 0.8]
    });
    assert_eq!(lit, SIZE * SIZE);
}
