//! The height solver alone, on two systems of an analytic sphere: the
//! integration of its exact normals (the rows of `integrate`) and the
//! shared height-from-polarization system (Smith's rows, boundary prior,
//! both light candidates), each solved by the sparse Cholesky factorisation
//! and by conjugate gradients with the multigrid preconditioner
//! (`lsq::Solver::with_iterative_min`), at 256², 512² and 1024². Before
//! timing it prints, per system and size, each solver's time, the
//! iterations and the normals' mean difference between the two (must stay
//! below 0.01°); a filter that matches no bench
//! (`cargo bench -p sfp-benchmarks --bench solver -- none`) prints only that.
//! Run: `cargo bench -p sfp-benchmarks --bench solver`.

use criterion::{Criterion, criterion_group, criterion_main};
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::metrics::angular_error_deg;
use sfp_core::view::View;
use sfp_reconstruct::input::Input;
use sfp_reconstruct::light::Lighting;
use sfp_reconstruct::prior::convexity_prior;
use sfp_reconstruct::solver::domain::Domain;
use sfp_reconstruct::solver::integrate::{self, normals_of};
use sfp_reconstruct::solver::lsq::{NormalEquations, Solver};
use sfp_reconstruct::solver::ordering::Ordering;
use sfp_reconstruct::system::{PixelData, System};
use std::time::{Duration, Instant};

const LIGHT: [f64; 3] = [0.35, 0.25, 0.9];

/// The sphere's view at `size²`.
fn view(size: usize) -> View {
    AnalyticScene {
        shape: Shape::Sphere,
        size,
        eta: 1.5,
        albedo: 0.8,
        light: LIGHT,
    }
    .render()
    .expect("analytic view")
}

/// The integration system of the sphere's exact normals on `domain`
/// (`integrate`'s rows).
fn integration<'a>(view: &View, domain: &'a Domain) -> NormalEquations<'a> {
    let normals = &view.gt.as_ref().expect("analytic ground truth").normals;
    integrate::equations(normals, domain).expect("normals of the view's size")
}

/// The height-from-polarization system's normal equations on `domain`
/// (both light candidates).
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
    for size in [256usize, 512, 1024] {
        let view = view(size);
        let input = Input::from_view(&view.input).expect("valid input");
        let domain = Domain::new(&input.mask);
        let systems = [
            ("integration", integration(&view, &domain)),
            ("polarization", equations(&input, &domain)),
        ];
        for (name, eq) in &systems {
            let direct = || Solver::new(Ordering::default()).with_iterative_min(usize::MAX);
            let iterative = || Solver::new(Ordering::default()).with_iterative_min(0);
            let start = Instant::now();
            let a = direct().solve(eq).expect("factorised");
            let seconds_direct = start.elapsed().as_secs_f64();
            let start = Instant::now();
            let b = iterative().solve(eq).expect("iterated");
            let seconds_iterative = start.elapsed().as_secs_f64();
            let mae =
                a.z.iter()
                    .zip(&b.z)
                    .map(|(a, b)| normals_difference(&domain, a, b))
                    .fold(0.0, f64::max);
            eprintln!(
                "solver {name} {size}²: {} unknowns, factorised {seconds_direct:.3} s, \
                 iterated {seconds_iterative:.3} s (setup {:.3} s, {} iterations for {} right-hand sides), \
                 normals differ by {mae:.5}° MAE",
                domain.len(),
                b.seconds_symbolic,
                b.iterations,
                b.z.len()
            );
            group.bench_function(format!("{name}/{size}/factorised"), |bench| {
                bench.iter(|| direct().solve(eq).expect("factorised"))
            });
            group.bench_function(format!("{name}/{size}/iterated"), |bench| {
                bench.iter(|| iterative().solve(eq).expect("iterated"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, solver);
criterion_main!(benches);
