//! Colour renders: one path per sample carries the three channels, which
//! differ only by their albedo. Each channel of a sphere with a coloured
//! albedo follows the closed-form single scattering (conventions.md §3)
//! with that channel's albedo, and the grey layers are the Rec. 709
//! luminance of the channels.

mod common;

use common::{EXAMPLE, parse, plane_coords, single_scatter};
use sfp_core::colour::luminance;
use sfp_renderer::render::{RenderOptions, render};

const LIGHT: [f64; 3] = [0.4, 0.3, 1.0];
const TINT: [f64; 3] = [1.0, 0.55, 0.2];

fn scene(extra_render: &str, spp: u32) -> String {
    EXAMPLE
        .replace("spp = 16", &format!("spp = {spp}"))
        .replace("width = 128", "width = 64")
        .replace("height = 128", "height = 64")
        .replace(
            "albedo = 0.8, eta = 1.5",
            "albedo = 0.8, eta = 1.5, tint = [1.0, 0.55, 0.2]",
        )
        .replace("max_depth = 1", extra_render)
}

#[test]
fn each_channel_follows_the_closed_form_with_its_albedo() {
    let out = render(
        &parse(&scene("colour = true\njitter = false\nmax_depth = 1", 1)),
        &RenderOptions::default(),
    )
    .unwrap();
    let gt = out.view.gt.as_ref().unwrap();
    let channels = gt.channel_stokes.as_ref().expect("per-channel Stokes");
    let grey = gt.stokes.as_ref().unwrap();
    let (w, h) = grey[0].size();
    let (mut lit, mut worst) = (0, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
            for (c, tint) in TINT.iter().enumerate() {
                let Some(e) = single_scatter(xc, yc, 0.0, LIGHT, 3.0, 0.8 * tint, 1.5) else {
                    continue;
                };
                if e[0] < 1e-3 {
                    continue;
                }
                lit += 1;
                for k in 0..3 {
                    let v = f64::from(*channels[c][k].get(x, y));
                    worst = worst.max((v - e[k]).abs() / e[0]);
                }
            }
            let rgb = [0, 1, 2].map(|c| f64::from(*channels[c][0].get(x, y)));
            let lum = f64::from(*grey[0].get(x, y));
            assert!((lum - luminance(rgb)).abs() <= 1e-6 * lum.max(1.0));
        }
    }
    assert!(lit > 3 * 2000, "{lit}");
    assert!(worst < 1e-4, "worst |Δs|/s0 = {worst:e}");
    // The sensor records each channel under one exposure: R above G above B.
    let rgb = out.view.input.colour.as_ref().expect("colour codes");
    let p = *rgb[0].get(32, 32);
    assert!(p[0] > p[1] && p[1] > p[2], "{p:?}");
}

#[test]
fn sampled_channels_keep_the_diffuse_polarization() {
    // Jittered samples and bounces: DoP and AoP of each channel's codes
    // match the closed form at the pixel centres within Monte-Carlo noise,
    // the spread over a pixel and quantization.
    let out = render(
        &parse(&scene("colour = true\nmax_depth = 4", 16)),
        &RenderOptions::default(),
    )
    .unwrap();
    let view = &out.view;
    let channels = view.input.channel_polarimetry().unwrap();
    let (w, h) = view.input.size();
    for (c, pm) in channels.iter().enumerate() {
        let (mut n, mut dop_err, mut aop_err) = (0, 0.0, 0.0);
        for y in 0..h {
            for x in 0..w {
                let (xc, yc) = plane_coords(x as f64 + 0.5, y as f64 + 0.5, w, h, 2.2);
                if xc * xc + yc * yc > 0.9 {
                    continue;
                }
                let Some(e) = single_scatter(xc, yc, 0.0, LIGHT, 3.0, 0.8 * TINT[c], 1.5) else {
                    continue;
                };
                let s = sfp_core::stokes::Stokes::new(e[0], e[1], e[2]);
                if e[0] <= 0.05 || s.dop() < 0.05 {
                    continue;
                }
                n += 1;
                dop_err += (f64::from(*pm.dop.get(x, y)) - s.dop()).abs();
                let d = (f64::from(*pm.aop.get(x, y)) - s.aop()).rem_euclid(std::f64::consts::PI);
                aop_err += d.min(std::f64::consts::PI - d).to_degrees();
            }
        }
        let (dop_err, aop_err) = (dop_err / n as f64, aop_err / n as f64);
        eprintln!("channel {c}: {n} pixels, mean |ΔDoP| {dop_err:.4}, mean |ΔAoP| {aop_err:.2}°");
        assert!(n > 300, "{n}");
        assert!(
            dop_err < 0.003 && aop_err < 0.5,
            "channel {c}: |ΔDoP| {dop_err}, |ΔAoP| {aop_err}°"
        );
    }
}
