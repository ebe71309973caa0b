//! Furnace tests: a sphere in a constant unpolarized environment of radiance
//! `L`. Each exit direction sees `L · albedo · T(θ_o) · 2∫T(θ)cosθ sinθ dθ`
//! (the Fresnel-weighted Lambert integral), and with `η = 1`, albedo 1 the
//! sphere disappears into the background (`s0 = L`). The sphere is convex, so
//! `max_depth = 4` exercises BSDF sampling and MIS without adding light.

mod common;

use common::{as_svbrdf, parse, plane_coords, t_avg};
use sfp_core::fresnel::diffuse_dop;
use sfp_renderer::render::{RenderOptions, render};

fn scene(albedo: f64, eta: f64, max_depth: u32) -> String {
    format!(
        r#"
[camera]
type = "orthographic"
width = 48
height = 48
extent = 2.2
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]

[render]
spp = 64
max_depth = {max_depth}
seed = 3

[[light]]
type = "environment"
radiance = 2.0

[[object]]
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = {{ type = "diffuse_polarized", albedo = {albedo}, eta = {eta} }}

[sensor]
noise = false
"#
    )
}

/// `2∫₀^{π/2} T(θ) cosθ sinθ dθ` by the midpoint rule.
fn hemispherical_transmittance(eta: f64) -> f64 {
    let n = 20_000;
    let h = std::f64::consts::FRAC_PI_2 / f64::from(n);
    (0..n)
        .map(|k| {
            let th = (f64::from(k) + 0.5) * h;
            2.0 * t_avg(th.cos(), eta) * th.cos() * th.sin() * h
        })
        .sum()
}

/// Sums over pixels whose centre is well inside the sphere:
/// (rendered s0, expected s0, rendered radial s, expected radial s,
/// rendered tangential s).
/// The sums for the `diffuse_polarized` material and for the same material
/// as `svbrdf` with constant maps, which must agree exactly.
fn sums(albedo: f64, eta: f64, max_depth: u32) -> [f64; 5] {
    let text = scene(albedo, eta, max_depth);
    let diffuse = sums_of(&parse(&text), albedo, eta);
    let svbrdf = sums_of(&parse(&as_svbrdf(&text)), albedo, eta);
    assert_eq!(diffuse, svbrdf);
    diffuse
}

fn sums_of(scene: &sfp_renderer::scene::Scene, albedo: f64, eta: f64) -> [f64; 5] {
    let out = render(scene, &RenderOptions::default()).unwrap();
    let gt = out.view.gt.unwrap();
    let (w, h) = gt.stokes.as_ref().unwrap()[0].size();
    let k = albedo * hemispherical_transmittance(eta) * 2.0;
    let mut acc = [0.0; 5];
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
            let s = [0, 1, 2].map(|c| f64::from(*gt.stokes.as_ref().unwrap()[c].get(x, y)));
            if xc.hypot(yc) > 1.05 {
                // Background: the environment itself, unpolarized.
                assert!((s[0] - 2.0).abs() < 1e-6 && s[1] == 0.0 && s[2] == 0.0);
                continue;
            }
            if xc.hypot(yc) > 0.95 {
                continue;
            }
            let nz = (1.0 - xc * xc - yc * yc).sqrt();
            let phi = yc.atan2(xc);
            let expect = k * t_avg(nz, eta);
            let (c2, s2) = ((2.0 * phi).cos(), (2.0 * phi).sin());
            acc[0] += s[0];
            acc[1] += expect;
            acc[2] += s[1] * c2 + s[2] * s2;
            acc[3] += expect * diffuse_dop(nz.acos(), eta);
            acc[4] += -s[1] * s2 + s[2] * c2;
        }
    }
    acc
}

#[test]
fn white_lambertian_furnace_is_invisible() {
    for depth in [1, 4] {
        let [r, e, rad, _, tan] = sums(1.0, 1.0, depth);
        println!("η=1, depth {depth}: s0 ratio {:.5}", r / e);
        assert!((r / e - 1.0).abs() < 3e-3, "depth {depth}: {}", r / e);
        assert!(rad.abs() < 1e-9 * r && tan.abs() < 1e-9 * r);
    }
}

#[test]
fn dielectric_furnace_matches_fresnel_integral_and_dop() {
    for depth in [1, 4] {
        let [r, e, rad, rad_e, tan] = sums(0.8, 1.5, depth);
        println!(
            "η=1.5, depth {depth}: s0 ratio {:.5}, radial ratio {:.5}, tangential/s0 {:.1e}",
            r / e,
            rad / rad_e,
            tan / r
        );
        assert!(
            (r / e - 1.0).abs() < 3e-3,
            "depth {depth}: s0 ratio {}",
            r / e
        );
        assert!(
            (rad / rad_e - 1.0).abs() < 5e-3,
            "depth {depth}: radial ratio {}",
            rad / rad_e
        );
        assert!((tan / r).abs() < 1e-3);
    }
}

/// The same furnace lit by a constant equirectangular EXR map: checks map
/// loading and that the importance-sampling density is normalised.
#[test]
fn constant_exr_environment_map_matches_constant_light() {
    let dir = tempfile::tempdir().unwrap();
    let map = sfp_core::Image::new(16, 8, 4.0f32);
    sfp_core::io::write_exr(&dir.path().join("env.exr"), &[("Y", &map)]).unwrap();
    let text = scene(0.8, 1.5, 2).replace("radiance = 2.0", "radiance = 0.5\nmap = \"env.exr\"");
    let scene =
        sfp_renderer::scene::Scene::from_toml(&text, &dir.path().join("scene.toml")).unwrap();
    let [r, e, rad, rad_e, _] = sums_of(&scene, 0.8, 1.5);
    println!(
        "EXR map: s0 ratio {:.5}, radial ratio {:.5}",
        r / e,
        rad / rad_e
    );
    assert!((r / e - 1.0).abs() < 3e-3 && (rad / rad_e - 1.0).abs() < 1e-2);
}

/// A Lambertian plane (`η = 1`) under a square area light: light sampling and
/// BSDF sampling, combined by MIS, must give `albedo/π · E` with `E` from a
/// quadrature of `∫ L cosθ cosθ_l / r² dA` at each pixel centre.
#[test]
fn area_light_irradiance_matches_quadrature() {
    let text = r#"
[camera]
type = "orthographic"
width = 6
height = 6
extent = 0.6
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]

[render]
spp = 4096
max_depth = 1
seed = 5

[[light]]
type = "area"
center = [0.2, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
size = 1.5
radiance = 2.0

[[object]]
shape = "plane"
center = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
size = 10.0
material = { type = "diffuse_polarized", albedo = 0.5, eta = 1.0 }
"#;
    let out = render(&parse(text), &RenderOptions::default()).unwrap();
    let gt = out.view.gt.unwrap();
    let (mut worst, mut sum_got, mut sum_expect) = (0.0f64, 0.0, 0.0);
    for y in 0..6 {
        for x in 0..6 {
            // Jittered over the pixel: integrate E over the footprint (3×3).
            let mut e = 0.0;
            for (sx, sy) in (0..3).flat_map(|i| (0..3).map(move |j| (i, j))) {
                let (px, py) = plane_coords(
                    x as f64 + (sx as f64 + 0.5) / 3.0,
                    y as f64 + (sy as f64 + 0.5) / 3.0,
                    6,
                    6,
                    0.6,
                );
                let m = 300;
                let h = 1.5 / f64::from(m);
                for i in 0..m {
                    for j in 0..m {
                        let lx = 0.2 - 0.75 + (f64::from(i) + 0.5) * h - px;
                        let ly = -0.75 + (f64::from(j) + 0.5) * h - py;
                        let r2 = lx * lx + ly * ly + 1.0;
                        e += 2.0 / (r2 * r2) * h * h / 9.0;
                    }
                }
            }
            let expect = 0.5 / std::f64::consts::PI * e;
            let got = f64::from(*gt.stokes.as_ref().unwrap()[0].get(x, y));
            worst = worst.max((got / expect - 1.0).abs());
            sum_got += got;
            sum_expect += expect;
        }
    }
    let total = sum_got / sum_expect - 1.0;
    println!("area light: worst pixel {worst:.2e}, all pixels {total:.2e} (relative)");
    // ~0.6% noise per pixel at 4096 spp; the 36-pixel sum has ~0.1%.
    assert!(worst < 3e-2 && total.abs() < 4e-3, "{worst} {total}");
}
