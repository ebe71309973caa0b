//! Single scattering off a sphere under a directional
//! light equals the closed-form pBRDF value (Fresnel-transmission-weighted
//! Lambert, DoP of conventions.md §3, AoP ∥ normal azimuth).

mod common;

use common::{EXAMPLE, as_svbrdf, parse, plane_coords, single_scatter, write_uv_sphere};
use sfp_core::stokes::Stokes;
use sfp_renderer::render::{RenderOptions, render};
use std::f64::consts::PI;

const LIGHT: [f64; 3] = [0.4, 0.3, 1.0];
/// `albedo · E / π`: s0 of a Lambertian facing the light.
const PEAK: f64 = 0.8 * 3.0 / std::f64::consts::PI;
/// Pixels darker than this (`cosθ_i ≲ 1e-3`, the terminator) are checked in
/// absolute terms only.
const TERMINATOR: f64 = 1e-3 * PEAK;

/// Closed form averaged over an `n × n` grid inside pixel `(x, y)`, and the
/// standard deviation of the closed form over that grid (the spread of a
/// single jittered sample).
fn footprint(x: usize, y: usize, w: usize, h: usize, roll: f64) -> ([f64; 3], [f64; 3]) {
    let n = 16;
    let (mut m1, mut m2) = ([0.0; 3], [0.0; 3]);
    for j in 0..n {
        for i in 0..n {
            let px = x as f64 + (i as f64 + 0.5) / n as f64;
            let py = y as f64 + (j as f64 + 0.5) / n as f64;
            let (xc, yc) = plane_coords(px, py, w, h, 2.2);
            let s = single_scatter(xc, yc, roll, LIGHT, 3.0, 0.8, 1.5).unwrap_or([0.0; 3]);
            for k in 0..3 {
                m1[k] += s[k] / (n * n) as f64;
                m2[k] += s[k] * s[k] / (n * n) as f64;
            }
        }
    }
    let sd = [0, 1, 2].map(|k| (m2[k] - m1[k] * m1[k]).max(0.0).sqrt());
    (m1, sd)
}

/// Renders `text` (`jitter = false`) and returns the worst |Δs_k|/s0 against
/// the closed form at the pixel centres, over covered and lit pixels.
fn compare_centres(text: &str, roll: f64) -> (f64, sfp_renderer::render::Rendered) {
    let out = render(&parse(text), &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let (w, h) = gt.stokes.as_ref().unwrap()[0].size();
    let mut worst = 0.0f64;
    let mut covered = 0;
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
            let rendered = [0, 1, 2].map(|k| f64::from(*gt.stokes.as_ref().unwrap()[k].get(x, y)));
            match single_scatter(xc, yc, roll, LIGHT, 3.0, 0.8, 1.5) {
                Some(e) if e[0] > 0.0 => {
                    covered += 1;
                    for k in 0..3 {
                        let err = (rendered[k] - e[k]).abs();
                        if e[0] > TERMINATOR {
                            worst = worst.max(err / e[0]);
                        } else {
                            // f32 geometry: cosθ_i carries ~1e-7 absolute error.
                            assert!(err < 1e-6 * PEAK, "({x}, {y}): |Δs{k}| = {err:e}");
                        }
                    }
                }
                _ => assert!(
                    rendered.iter().all(|&v| v.abs() < 1e-6),
                    "({x}, {y}) {rendered:?}"
                ),
            }
        }
    }
    assert!(covered > 9000, "{covered} lit pixels");
    (worst, out)
}

/// Mean |ΔDoP| and mean |ΔAoP| (degrees) from the rendered 16-bit polarizer
/// images against the closed form, for pixels with r < 0.95 and enough DoP
/// for the AoP to be defined.
fn polarimetry_errors(out: &sfp_renderer::render::Rendered, roll: f64) -> (f64, f64) {
    let pol = &out.view.input.pol;
    let (w, h) = pol[0].size();
    let (mut dop_err, mut aop_err, mut n_dop, mut n_aop) = (0.0, 0.0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
            if xc.hypot(yc) > 0.95 {
                continue;
            }
            let Some(e) = single_scatter(xc, yc, roll, LIGHT, 3.0, 0.8, 1.5) else {
                continue;
            };
            let expect = Stokes::new(e[0], e[1], e[2]);
            let i = [0, 1, 2, 3].map(|c| f64::from(*pol[c].get(x, y)));
            let got = Stokes::from_four(i[0], i[1], i[2], i[3]);
            if got.s0 < 0.05 * 65535.0 {
                continue; // shadowed side
            }
            dop_err += (got.dop() - expect.dop()).abs();
            n_dop += 1;
            if expect.dop() > 0.01 {
                let d = (got.aop() - expect.aop()).abs();
                aop_err += d.min(std::f64::consts::PI - d).to_degrees();
                n_aop += 1;
            }
        }
    }
    assert!(n_dop > 1000 && n_aop > 500, "{n_dop} {n_aop}");
    (dop_err / f64::from(n_dop), aop_err / f64::from(n_aop))
}

fn no_jitter(text: &str) -> String {
    text.replace("seed = 7", "seed = 7\njitter = false")
        .replace("spp = 16", "spp = 1")
}

#[test]
fn pixel_centres_match_closed_form() {
    // Also as an `svbrdf` material with constant maps.
    for text in [no_jitter(EXAMPLE), as_svbrdf(&no_jitter(EXAMPLE))] {
        let (worst, out) = compare_centres(&text, 0.0);
        println!("max |Δs|/s0 = {worst:.2e}");
        assert!(worst < 1e-4, "max |Δs|/s0 = {worst:e}");
        let (dop, aop) = polarimetry_errors(&out, 0.0);
        println!("mean |ΔDoP| = {dop:.2e}, mean |ΔAoP| = {aop:.3}°");
        assert!(dop < 1e-3 && aop < 0.1, "ΔDoP {dop}, ΔAoP {aop}°");
    }
}

/// With jitter, each pixel is a 64-sample mean: its error against the
/// footprint average must look like sampling noise (z-scores from the closed
/// form's spread over the pixel), and the image total must be unbiased.
#[test]
fn jittered_samples_match_footprint_average() {
    let spp = 64.0;
    let text = EXAMPLE.replace("spp = 16", "spp = 64");
    let out = render(&parse(&text), &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let (w, h) = gt.stokes.as_ref().unwrap()[0].size();
    let (mut z2, mut zmax, mut n) = (0.0f64, 0.0f64, 0usize);
    let (mut sum_r, mut sum_e) = (0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let (mean, sd) = footprint(x, y, w, h, 0.0);
            sum_e += mean[0];
            sum_r += f64::from(*gt.stokes.as_ref().unwrap()[0].get(x, y));
            if mean[0] <= TERMINATOR {
                continue;
            }
            for k in 0..3 {
                // Floor: f32 rounding of the renderer (~1e-6 relative).
                let se = (sd[k] * sd[k] / spp + (1e-5 * mean[0]).powi(2)).sqrt();
                let z = (f64::from(*gt.stokes.as_ref().unwrap()[k].get(x, y)) - mean[k]) / se;
                z2 += z * z;
                zmax = zmax.max(z.abs());
                n += 1;
            }
        }
    }
    let mean_z2 = z2 / n as f64;
    let total = sum_r / sum_e - 1.0;
    println!("mean z² = {mean_z2:.3}, max |z| = {zmax:.2}, s0 sum rel. error = {total:.2e}");
    assert!((0.7..1.3).contains(&mean_z2), "mean z² = {mean_z2}");
    assert!(zmax < 8.0, "max |z| = {zmax}");
    assert!(total.abs() < 5e-4, "total s0 off by {total:e}");
}

#[test]
fn camera_roll_rotates_aop() {
    for deg in [30.0f64, 45.0, 90.0, 135.0] {
        let beta = deg.to_radians();
        let up = format!("up = [{}, {}, 0.0]", -beta.sin(), beta.cos());
        let text = no_jitter(EXAMPLE).replace("up = [0.0, 1.0, 0.0]", &up);
        let (worst, out) = compare_centres(&text, beta);
        assert!(worst < 1e-4, "roll {deg}°: max |Δs|/s0 = {worst:e}");
        let (dop, aop) = polarimetry_errors(&out, beta);
        assert!(
            dop < 1e-3 && aop < 0.1,
            "roll {deg}°: ΔDoP {dop}, ΔAoP {aop}°"
        );
    }
}

#[test]
fn tessellated_obj_sphere_matches_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    write_uv_sphere(&dir.path().join("sphere.obj"), 128, 256);
    let text = no_jitter(EXAMPLE).replace(
        "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        "mesh = \"sphere.obj\"",
    );
    let scene =
        sfp_renderer::scene::Scene::from_toml(&text, &dir.path().join("scene.toml")).unwrap();
    let out = render(&scene, &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let (w, h) = gt.stokes.as_ref().unwrap()[0].size();
    let mut worst = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
            if xc.hypot(yc) > 0.95 {
                continue;
            }
            let e = single_scatter(xc, yc, 0.0, LIGHT, 3.0, 0.8, 1.5).unwrap();
            if e[0] < 0.05 {
                continue;
            }
            for k in 0..3 {
                let r = f64::from(*gt.stokes.as_ref().unwrap()[k].get(x, y));
                worst = worst.max((r - e[k]).abs() / e[0]);
            }
        }
    }
    let (dop, aop) = polarimetry_errors(&out, 0.0);
    println!("mesh: max |Δs|/s0 = {worst:.2e}, mean |ΔDoP| = {dop:.2e}, mean |ΔAoP| = {aop:.3}°");
    assert!(worst < 1e-2, "max |Δs|/s0 = {worst:e}");
    assert!(dop < 1e-3 && aop < 0.2, "ΔDoP {dop}, ΔAoP {aop}°");
}

/// Perspective camera: each pixel's ray, hit point, normal, Fresnel terms and
/// the exit polarization direction (in the plane of `n` and `ω_o`) are
/// computed here in f64 and projected onto the camera's Stokes frame
/// (`x` = camera right made perpendicular to the ray, `y = ω_o × x`).
#[test]
fn perspective_pixel_centres_match_closed_form() {
    use sfp_core::fresnel::diffuse_dop;
    let (w, h, fov) = (64usize, 48usize, 40f64.to_radians());
    let text = no_jitter(EXAMPLE)
        .replace("type = \"orthographic\"", "type = \"perspective\"")
        .replace("extent = 2.2", &format!("fov = {}", fov.to_degrees()))
        .replace("width = 128", &format!("width = {w}"))
        .replace("height = 128", &format!("height = {h}"))
        .replace("position = [0.0, 0.0, 5.0]", "position = [0.0, 0.0, 4.0]");
    let out = render(&parse(&text), &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let norm = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        a.map(|v| v / l)
    };
    let l = norm(LIGHT);
    let tan = (0.5 * fov).tan();
    let (mut worst, mut checked) = (0.0f64, 0);
    for y in 0..h {
        for x in 0..w {
            let sx = (2.0 * (x as f64 + 0.5) / w as f64 - 1.0) * tan;
            let sy = (1.0 - 2.0 * (y as f64 + 0.5) / h as f64) * tan * h as f64 / w as f64;
            let d = norm([sx, sy, -1.0]);
            let o = [0.0, 0.0, 4.0];
            // |o + t d|² = 1.
            let b = dot(o, d);
            let disc = b * b - (dot(o, o) - 1.0);
            if disc <= 0.0 {
                continue;
            }
            let t = -b - disc.sqrt();
            let n = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
            let wo = d.map(|v| -v);
            let (cos_i, cos_o) = (dot(n, l), dot(n, wo));
            let s0 = 0.8 / PI
                * 3.0
                * cos_i.max(0.0)
                * common::t_avg(cos_i, 1.5)
                * common::t_avg(cos_o, 1.5);
            if s0 <= TERMINATOR {
                continue;
            }
            let dop = diffuse_dop(cos_o.acos(), 1.5);
            let ep = norm([0, 1, 2].map(|k| n[k] - cos_o * wo[k]));
            let fx = norm([0, 1, 2].map(|k| [1.0, 0.0, 0.0][k] - d[0] * d[k]));
            let fy = [
                wo[1] * fx[2] - wo[2] * fx[1],
                wo[2] * fx[0] - wo[0] * fx[2],
                wo[0] * fx[1] - wo[1] * fx[0],
            ];
            let aop = dot(ep, fy).atan2(dot(ep, fx));
            let e = [
                s0,
                s0 * dop * (2.0 * aop).cos(),
                s0 * dop * (2.0 * aop).sin(),
            ];
            for (img, want) in gt.stokes.as_ref().unwrap().iter().zip(e) {
                worst = worst.max((f64::from(*img.get(x, y)) - want).abs() / s0);
            }
            checked += 1;
        }
    }
    println!("perspective: {checked} pixels, max |Δs|/s0 = {worst:.2e}");
    assert!(
        checked > 500 && worst < 1e-4,
        "{checked} pixels, max |Δs|/s0 = {worst:e}"
    );
}

/// Pure specular lobe (albedo 0) under a directional light, orthographic:
/// every pixel reflects through the same half vector `h = normalize(l + v)`,
/// so the light is s-polarized with respect to `h` (here along camera `y`:
/// AoP = 90°, `s1 = −ρ_s s0`, `s2 = 0`) with DoP `ρ_s(θ_d)`, and
/// `s0 = E · D(n·h) G1(n·v) G1(n·l) R̄(θ_d) / (4 n·v)` (GGX, Smith).
#[test]
fn specular_lobe_matches_microfacet_closed_form() {
    use sfp_core::fresnel::{reflectance, specular_dop};
    let (alpha, eta, e) = (0.3f64, 1.5f64, 3.0f64);
    let l = [0.6f64, 0.0, 0.8];
    let text = no_jitter(EXAMPLE)
        .replace("direction = [0.4, 0.3, 1.0]", "direction = [0.6, 0.0, 0.8]")
        .replace(
            "albedo = 0.8, eta = 1.5 }",
            "albedo = 0.0, eta = 1.5, specular = 1.0, roughness = 0.3 }",
        );
    // The `svbrdf` material with constant maps renders the same lobe.
    let out = render(&parse(&text), &RenderOptions::default()).unwrap();
    let same = render(&parse(&as_svbrdf(&text)), &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let same = same.view.gt.unwrap();
    assert!(same.stokes == gt.stokes && same.normals == gt.normals);
    let (w, h) = gt.stokes.as_ref().unwrap()[0].size();
    let hv = {
        let v = [l[0], l[1], l[2] + 1.0];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / n)
    };
    let cos_d = hv[0] * l[0] + hv[1] * l[1] + hv[2] * l[2];
    let g1 = |c: f64| 2.0 / (1.0 + (1.0 + alpha * alpha * (1.0 - c * c) / (c * c)).sqrt());
    let (rs, rp) = reflectance(cos_d, eta);
    let dop = specular_dop(cos_d.acos(), eta);
    let (mut worst, mut checked) = (0.0f64, 0);
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
            if xc.hypot(yc) >= 0.98 {
                continue;
            }
            let n = [xc, yc, (1.0 - xc * xc - yc * yc).sqrt()];
            let (cos_o, cos_i) = (n[2], n[0] * l[0] + n[2] * l[2]);
            if cos_i <= 0.05 {
                continue;
            }
            let cos_h = n[0] * hv[0] + n[1] * hv[1] + n[2] * hv[2];
            let k = cos_h * cos_h * (alpha * alpha - 1.0) + 1.0;
            let d = alpha * alpha / (std::f64::consts::PI * k * k);
            let s0 = e * d * g1(cos_o) * g1(cos_i) * 0.5 * (rs + rp) / (4.0 * cos_o);
            let expect = [s0, -dop * s0, 0.0];
            for (img, want) in gt.stokes.as_ref().unwrap().iter().zip(expect) {
                worst = worst.max((f64::from(*img.get(x, y)) - want).abs() / s0);
            }
            checked += 1;
        }
    }
    println!("specular: {checked} pixels, max |Δs|/s0 = {worst:.2e}, DoP {dop:.4}");
    assert!(checked > 5000 && worst < 1e-4, "max |Δs|/s0 = {worst:e}");
}

/// A coarse mesh lit from the camera: every pixel that sees the object is lit.
/// Along the silhouette the interpolated normal of a facet straddling the limb
/// can face away from the camera; the visible facet's own normal shades there
/// (and is the ground truth) instead of leaving the pixel black.
#[test]
fn coarse_mesh_silhouette_is_lit_and_matches_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    write_uv_sphere(&dir.path().join("coarse.obj"), 8, 16);
    let text = no_jitter(EXAMPLE)
        .replace(
            "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
            "mesh = \"coarse.obj\"\nrotate = [63.0, 21.0, 0.0]",
        )
        .replace("direction = [0.4, 0.3, 1.0]", "direction = [0.0, 0.0, 1.0]");
    let scene =
        sfp_renderer::scene::Scene::from_toml(&text, &dir.path().join("scene.toml")).unwrap();
    let out = render(&scene, &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let mask = out.view.input.mask.as_ref().unwrap();
    let (w, h) = mask.size();
    let (mut covered, mut dark) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            if !*mask.get(x, y) {
                continue;
            }
            covered += 1;
            let n = gt.normals.get(x, y);
            assert!(n[2] > 0.0, "ground-truth normal faces away at {x},{y}");
            if *gt.stokes.as_ref().unwrap()[0].get(x, y) <= 0.0 {
                dark += 1;
            }
        }
    }
    println!("coarse mesh: {dark} of {covered} covered pixels unlit");
    assert!(
        covered > 1000 && dark == 0,
        "{dark} of {covered} covered pixels unlit"
    );
}
