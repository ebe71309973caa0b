//! The ground truth of the diffuse/specular mixture (`gt/specular_stokes.exr`,
//! conventions.md §5): the specular part a mixed material's view records
//! equals the view of the same sphere with the specular lobe alone, and the
//! rest equals the view with the diffuse lobe alone, within Monte-Carlo
//! noise; views without a specular lobe record no mixture.

mod common;

use common::{EXAMPLE, parse};
use sfp_core::{Image, Mask};
use sfp_renderer::render::{RenderOptions, render};

/// The example sphere at 32², with `material`, a uniform environment (so
/// light reaches the first vertex after a bounce too) and `spp` samples.
fn scene(material: &str, spp: u32) -> String {
    EXAMPLE
        .replace("width = 128", "width = 32")
        .replace("height = 128", "height = 32")
        .replace("spp = 16", &format!("spp = {spp}"))
        .replace("max_depth = 1", "max_depth = 3")
        .replace(
            r#"material = { type = "diffuse_polarized", albedo = 0.8, eta = 1.5 }"#,
            &format!(r#"material = {{ type = "diffuse_polarized", eta = 1.5, {material} }}"#),
        )
        + "\n[[light]]\ntype = \"environment\"\nradiance = 0.3\n"
}

/// `Σ s0`, `Σ |s1|`, `Σ |s2|` over the sphere's pixels (the background
/// shows the environment itself, which no surface reflected).
fn sums(s: &[Image<f32>; 3], mask: &Mask) -> [f64; 3] {
    [0, 1, 2].map(|k| {
        s[k].data()
            .iter()
            .zip(mask.data())
            .filter(|(_, m)| **m)
            .map(|(&v, _)| f64::from(v).abs())
            .sum()
    })
}

type Stokes = [Image<f32>; 3];

fn stokes_of(text: &str) -> (Stokes, Option<Stokes>, Mask) {
    let out = render(&parse(text), &RenderOptions::default()).unwrap();
    let gt = out.view.gt.unwrap();
    (
        gt.stokes.unwrap(),
        gt.specular_stokes,
        out.view.input.mask.unwrap(),
    )
}

#[test]
fn the_specular_part_is_the_specular_lobes_view() {
    let lobes = "specular = 0.7, roughness = 0.25";
    let (mixed, part, mask) = stokes_of(&scene(&format!("albedo = 0.6, {lobes}"), 256));
    let part = part.expect("a specular lobe records the mixture");
    let (specular_only, ..) = stokes_of(&scene(&format!("albedo = 0.0, {lobes}"), 256));
    let (diffuse_only, none, _) = stokes_of(&scene("albedo = 0.6, specular = 0.0", 256));
    assert!(none.is_none(), "no specular lobe, no mixture recorded");
    let diffuse_part: Stokes = [0, 1, 2].map(|k| {
        Image::from_vec(
            32,
            32,
            mixed[k]
                .data()
                .iter()
                .zip(part[k].data())
                .map(|(a, b)| a - b)
                .collect(),
        )
        .unwrap()
    });
    let total = sums(&mixed, &mask)[0];
    for (name, got, want) in [
        ("specular", sums(&part, &mask), sums(&specular_only, &mask)),
        (
            "diffuse",
            sums(&diffuse_part, &mask),
            sums(&diffuse_only, &mask),
        ),
    ] {
        for k in 0..3 {
            // Monte-Carlo noise of ~660 pixels × 256 samples, relative to
            // the whole image's s0.
            assert!(
                (got[k] - want[k]).abs() < 0.01 * total,
                "{name} s{k}: {} vs {} (Σs0 {total})",
                got[k],
                want[k]
            );
        }
    }
    // Both parts matter here, so the test can tell them apart.
    let share = sums(&part, &mask)[0] / total;
    assert!((0.02..0.6).contains(&share), "specular share {share}");
}
