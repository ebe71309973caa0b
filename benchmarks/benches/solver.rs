//! The height solver alone: the shared height-from-polarization system of
//! an analytic sphere (Smith's rows, boundary prior, both light candidates)
//! solved by the sparse Cholesky factorisation and by conjugate gradients
//! with the multigrid preconditioner (`lsq::Solver::with_iterative_min`),
//! at 256² and 512². Before timing it prints, per size, each solver's
//! iterations and time and the normals' mean difference between the two
//! (must stay below 0.01°).
//! Run: `cargo bench -p sfp-benchmarks --bench solver`.

use criterion::{Criterion, criterion_group, criterion_main};
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::metrics::angular_error_deg;
use sfp_reconstruct::Input;
use sfp_reconstruct::domain::Domain;
use sfp_reconstruct::integrate::normals_of;
use sfp_reconstruct::light::Lighting;
use sfp_reconstruct::lsq::{NormalEquations, Solver};
use sfp_reconstruct::ordering::Ordering;
use sfp_reconstruct::prior::convexity_prior;
use sfp_reconstruct::system::{PixelData, System};
use std::time::{Duration, Instant};

const LIGHT: [f64; 3] = [0.35, 0.25, 0.9];

/// The sphere's input at `size²`.
fn input(size: usize) -> Input {
    let view = AnalyticScene {
        shape: Shape::Sphere,
        size,
        eta: 1.5,
        albedo: 0.8,
        light: LIGHT,
    }
    .render()
    .expect("analytic view");
    Input::from_view(&view.input).expect("valid input")
}

/// The system's normal equations on `domain` (both light candidates).
fn equations<'a>(input: &Input, domain: &'a Domain) -> NormalEquations<'a> {
    let (theta, _) = input.zenith(1.5);
    let data = PixelData::gather(domain, input, &theta, None).expect("pixel data");
    let prior = convexity_prior(&input.mask, 5.0);
    let system = System {
        domain,
        data: &data,
        prior: &prior,
        lambda: 0.1,
        relative: None,
    };
    let lighting = Lighting {
        ambient: 0.0,
        vector: LIGHT.map(|v| v * 0.8),
    };
    let mut eq = NormalEquations::with_right_hand_sides(domain, 2);
    system.add_base_rows(&mut eq);
    system.add_shading_rows(&mut eq, &lighting, 2);
    eq
}

/// Mean angle (degrees) between the normals of two height vectors.
fn normals_difference(domain: &Domain, a: &[f64], b: &[f64]) -> f64 {
    let (a, b) = (normals_of(domain, a), normals_of(domain, b));
    a.iter()
        .zip(&b)
        .filter_map(|(p, q)| angular_error_deg(*p, *q))
        .sum::<f64>()
        / a.len() as f64
}

fn solver(c: &mut Criterion) {
    let mut group = c.benchmark_group("solver");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    for size in [256usize, 512] {
        let input = input(size);
        let domain = Domain::new(&input.mask);
        let eq = equations(&input, &domain);
        let direct = || Solver::new(Ordering::default()).with_iterative_min(usize::MAX);
        let iterative = || Solver::new(Ordering::default()).with_iterative_min(0);
        let start = Instant::now();
        let a = direct().solve(&eq).expect("factorised");
        let seconds_direct = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let b = iterative().solve(&eq).expect("iterated");
        let seconds_iterative = start.elapsed().as_secs_f64();
        let mae = (0..2)
            .map(|i| normals_difference(&domain, &a.z[i], &b.z[i]))
            .fold(0.0, f64::max);
        eprintln!(
            "solver {size}²: {} unknowns, factorised {seconds_direct:.3} s, \
             iterated {seconds_iterative:.3} s ({} iterations for 2 right-hand sides), \
             normals differ by {mae:.5}° MAE",
            domain.len(),
            b.iterations
        );
        group.bench_function(format!("{size}/factorised"), |bench| {
            bench.iter(|| direct().solve(&eq).expect("factorised"))
        });
        group.bench_function(format!("{size}/iterated"), |bench| {
            bench.iter(|| iterative().solve(&eq).expect("iterated"))
        });
    }
    group.finish();
}

criterion_group!(benches, solver);
criterion_main!(benches);
