//! Albedo textures: an OBJ quad with texture coordinates, facing an
//! orthographic camera and a light along the view axis (`η = 1`, so
//! `s0 = albedo · E / π`). The image must appear upright (OBJ `v` is up) and
//! each quadrant must carry its texel's sRGB-decoded albedo.

mod common;

use sfp_renderer::render::{RenderOptions, render};
use sfp_renderer::scene::Scene;

fn srgb(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn textured_quad_is_upright_and_scaled_by_texels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Top row: 255, 128; bottom row: 64, 32.
    let texels = [255u8, 128, 64, 32];
    image::GrayImage::from_raw(2, 2, texels.to_vec())
        .unwrap()
        .save(d.join("checker.png"))
        .unwrap();
    std::fs::write(
        d.join("quad.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
         f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    let text = common::EXAMPLE
        .replace("extent = 2.2", "extent = 2.0")
        .replace("width = 128", "width = 2")
        .replace("height = 128", "height = 2")
        .replace("seed = 7", "seed = 7\njitter = false")
        .replace("spp = 16", "spp = 1")
        .replace("direction = [0.4, 0.3, 1.0]", "direction = [0.0, 0.0, 1.0]")
        .replace(
            "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
            "mesh = \"quad.obj\"",
        )
        .replace(
            "albedo = 0.8, eta = 1.5",
            "albedo = 0.9, albedo_texture = \"checker.png\", eta = 1.0",
        );
    let scene = Scene::from_toml(&text, &d.join("scene.toml")).unwrap();
    let out = render(&scene, &RenderOptions::default()).unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    // Each pixel centre maps to one texel centre (uv = 0.25 or 0.75).
    for (px, py) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let albedo = 0.9 * srgb(texels[py * 2 + px]);
        let expect = albedo * 3.0 / std::f64::consts::PI;
        let got = f64::from(*gt.stokes.as_ref().unwrap()[0].get(px, py));
        assert!(
            (got / expect - 1.0).abs() < 1e-4,
            "pixel ({px}, {py}): {got} vs {expect}"
        );
        let gt_albedo = f64::from(*gt.albedo.as_ref().unwrap().get(px, py));
        assert!((gt_albedo - albedo).abs() < 1e-5, "{gt_albedo} vs {albedo}");
    }
    // Upright: the top-left quadrant is the brightest, bottom-right the darkest.
    let s = |x, y| *gt.stokes.as_ref().unwrap()[0].get(x, y);
    assert!(s(0, 0) > s(1, 0) && s(1, 0) > s(0, 1) && s(0, 1) > s(1, 1));
}
