//! Reconstructions do not depend on the number of threads: the same view
//! gives bit-identical normals and heights with 1 and 2 rayon threads, also
//! when the least-squares system is split over the two cores (as every
//! component above 2,000 pixels is).

use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_reconstruct::input::Input;
use sfp_reconstruct::method::Method;
use sfp_reconstruct::methods::atkinson::Atkinson;
use sfp_reconstruct::methods::mahmoud::Mahmoud;
use sfp_reconstruct::methods::smith::Smith;
use sfp_reconstruct::smsfp::Smsfp;

#[test]
fn one_and_two_threads_give_identical_results() {
    let view = AnalyticScene {
        shape: Shape::Blobs,
        size: 128,
        light: [0.3, -0.2, 0.9],
        ..Default::default()
    }
    .render()
    .unwrap();
    let input = Input::from_view(&view.input).unwrap();
    let methods: [Box<dyn Method + Sync>; 4] = [
        Box::new(Smith::default()),
        Box::new(Smsfp::default()),
        Box::new(Atkinson::default()),
        Box::new(Mahmoud::default()),
    ];
    for method in &methods {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| method.reconstruct(&input).unwrap())
        };
        let (one, two) = (run(1), run(2));
        let name = &one.run.method;
        assert!(
            one.normals.data() == two.normals.data(),
            "{name}: normals differ"
        );
        let bits =
            |h: &sfp_core::Image<f32>| h.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&one.height),
            bits(&two.height),
            "{name}: heights differ"
        );
    }
}
