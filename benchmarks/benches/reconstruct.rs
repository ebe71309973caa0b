//! Speed of the Smith et al. baseline (issue 4): a full reconstruction of an
//! analytic sphere view at 512² (~166k mask pixels; target < 2 s on 2 cores)
//! and 1024² (~666k pixels; target < 8 s, < 4 GB), with the light estimated
//! (two solves: the convex/concave pair, sharing one symbolic factorisation).
//!
//! Before timing, each size prints one run's breakdown (assembly vs symbolic
//! vs numeric solve) and its MAE, so the closing note can quote them.
//! Run: `cargo bench -p sfp-benchmarks --bench reconstruct`.

use criterion::{Criterion, criterion_group, criterion_main};
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::metrics::evaluate;
use sfp_reconstruct::ordering::Ordering;
use sfp_reconstruct::smith::Smith;
use sfp_reconstruct::{Input, Method};
use std::time::Duration;

fn smith(c: &mut Criterion) {
    let mut group = c.benchmark_group("smith");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    for size in [512usize, 1024] {
        let view = AnalyticScene {
            shape: Shape::Sphere,
            size,
            eta: 1.5,
            albedo: 0.8,
            light: [0.35, 0.25, 0.9],
        }
        .render()
        .expect("analytic view");
        let input = Input::from_view(&view.input).expect("valid input");
        let gt = view.gt.as_ref().expect("ground truth");
        for ordering in [Ordering::NestedDissection, Ordering::Amd] {
            let method = Smith {
                ordering,
                ..Smith::default()
            };
            let rec = method.reconstruct(&input).expect("reconstruction");
            let m = evaluate(&rec.normals, &gt.normals, &input.mask).expect("metrics");
            eprintln!(
                "smith {size}² {}: {} pixels, MAE {:.3}°, timings {}",
                ordering.name(),
                input.mask.count(),
                m.mae_deg,
                rec.run["timings"]
            );
            group.bench_function(format!("{size}/{}", ordering.name()), |b| {
                b.iter(|| method.reconstruct(&input).expect("reconstruction"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, smith);
criterion_main!(benches);
