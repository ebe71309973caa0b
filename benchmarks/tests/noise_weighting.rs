//! SMSfP's noise-weighted azimuth rows (`azimuth_noise_deg`) on analytic
//! views exposed by the sensor model at 1250 e⁻ full well, as the sweeps
//! expose them: a dim sphere keeps its roundness, and a relief whose rim is
//! a crease (no occluding contour) is not handed to a prior that holds only
//! a few noise-made contour pixels.

use sfp_benchmarks::sweep::exposure::noisy_input;
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::metrics::evaluate;
use sfp_reconstruct::method::Method;
use sfp_reconstruct::smsfp::Smsfp;
use sfp_renderer::scene::SensorDesc;

/// SMSfP's MAE (degrees) on `shape` exposed with noise `seed`, with
/// `azimuth_noise_deg` 0 and 10.
fn mae(shape: Shape, seed: u64) -> (f64, f64) {
    let view = AnalyticScene {
        shape,
        ..AnalyticScene::default()
    }
    .render()
    .unwrap();
    let sensor = SensorDesc {
        full_well: 1250.0,
        noise: true,
        ..SensorDesc::default()
    };
    let input = noisy_input(&view, &sensor, seed, 0).unwrap();
    let gt = &view.gt.as_ref().unwrap().normals;
    let run = |deg: f64| {
        let method = Smsfp {
            azimuth_noise_deg: deg,
            ..Smsfp::default()
        };
        let rec = method.reconstruct(&input).unwrap();
        evaluate(&rec.normals, gt, &input.mask).unwrap().mae_deg
    };
    (run(0.0), run(10.0))
}

#[test]
fn a_dim_sphere_keeps_its_roundness() {
    let (uniform, weighted) = mae(Shape::Sphere, 0);
    println!("sphere 128², 1250 e⁻: {uniform:.2}° uniform, {weighted:.2}° weighted");
    assert!(weighted < uniform - 3.0, "{weighted} vs {uniform}");
}

#[test]
fn a_relief_without_contours_keeps_its_azimuth_rows() {
    // Seeds whose noise lifts a few rim pixels to a grazing zenith with an
    // AoP that passes the contour test: with the rows released wherever a
    // region had any trusted pixel, these came out 12–17° worse (seed 3:
    // 36.78°). The flat solve gives 22–24°, and the AoP oriented by
    // continuity 19–25° (its rows carry each pixel's AoP confidence, so the
    // two weightings orient it differently; seed 9 loses 1.8° weighted).
    for seed in [3, 4, 9] {
        let (uniform, weighted) = mae(Shape::Blobs, seed);
        println!(
            "blobs 128², 1250 e⁻, seed {seed}: {uniform:.2}° uniform, {weighted:.2}° weighted"
        );
        assert!(weighted < 26.0, "seed {seed}: {weighted} vs {uniform}");
    }
}
