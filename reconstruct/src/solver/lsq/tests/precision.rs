//! The precision ladder of [`Solver`]: single, floored single and double
//! precision, which one each system starts from, and that every rung gives
//! double precision's answer.

use super::*;

#[test]
fn mixed_precision_gives_the_double_precision_solution() {
    // The random problem (whole components) and a disc split in two
    // halves, factorised in single precision and refined, against the
    // double-precision factorisation.
    let mut rng = Pcg64::seed_from_u64(12);
    let (small, small_rows) = random_problem(&mut rng);
    let (disc, disc_rows) = disc_problem(&mut rng, 120, 100, 46.0, false);
    for (domain, rows) in [(&small, &small_rows), (&disc, &disc_rows)] {
        let eq = two_right_hand_sides(domain, rows);
        let solve = |mixed_min| {
            Solver::new(Ordering::NestedDissection)
                .with_split_min(2_000)
                .with_mixed_min(mixed_min)
                .solve(&eq)
                .unwrap()
        };
        let (double, mixed) = (solve(usize::MAX), solve(0));
        assert_same_solutions(&double.z, &mixed.z, "mixed precision");
    }
}

/// Solves `eq` twice with `solver` and checks each answer against
/// double precision's and the precision remembered after each.
fn assert_precision(solver: &mut Solver, eq: &NormalEquations, expected: Precision) {
    let double = Solver::new(Ordering::NestedDissection)
        .with_mixed_min(usize::MAX)
        .solve(eq)
        .unwrap();
    for _ in 0..2 {
        let sol = solver.solve(eq).unwrap();
        assert!(
            solver.cache.iter().all(|c| c.precision == expected),
            "{:?}",
            solver.cache.iter().map(|c| c.precision).collect::<Vec<_>>()
        );
        assert_same_solutions(&double.z, &sol.z, "mixed precision");
    }
}

#[test]
fn a_system_single_precision_cannot_factorise_is_factorised_in_double_next_time() {
    // Azimuth rows alone, every azimuth radial, on a disc: any radial
    // profile z(r) satisfies them, so those modes are held by the
    // membrane alone (relative 1e-9, below single precision), and there
    // are too many of them (one per radius) for the floored factor's
    // refinement. A well-posed system on the same kind of disc
    // factorises in single precision and keeps doing so.
    let mut rng = Pcg64::seed_from_u64(13);
    let (disc, well_posed) = disc_problem(&mut rng, 60, 60, 26.0, false);
    let ops = Operators::new(&disc);
    let mut radial = NormalEquations::new(&disc);
    for k in 0..disc.len() {
        let (x, y) = disc.pixel(k);
        let psi = (30.0 - y as f64).atan2(x as f64 - 30.0);
        if let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) {
            radial.add(&dx.combine(psi.sin(), &dy, -psi.cos()), 0.0, 1.0);
            // A gradient along the radius, to solve for.
            radial.add(&dx, 0.01 * psi.cos(), 1e-3);
        }
    }
    for floored_min in [0, usize::MAX] {
        let mut solver = Solver::new(Ordering::NestedDissection)
            .with_mixed_min(0)
            .with_floored_min(floored_min);
        assert_precision(&mut solver, &radial, Precision::Double);
    }
    let mut solver = Solver::new(Ordering::NestedDissection)
        .with_mixed_min(0)
        .with_floored_min(0);
    assert_precision(
        &mut solver,
        &two_right_hand_sides(&disc, &well_posed),
        Precision::Single,
    );
}

#[test]
fn a_component_larger_than_one_single_precision_failed_on_skips_it() {
    // Two discs in one system: the smaller (first in raster order)
    // carries the radial azimuth rows above, which single precision
    // cannot factorise; the larger, random gradient rows, which it can
    // alone. Solved together, the larger starts at the floored factor,
    // and both keep double precision's answer.
    let (w, h) = (120, 70);
    let small = |x: usize, y: usize| (x as f64 - 20.0).powi(2) + (y as f64 - 14.0).powi(2) < 144.0;
    let large = |x: usize, y: usize| (x as f64 - 75.0).powi(2) + (y as f64 - 40.0).powi(2) < 676.0;
    let domain = Domain::new(&Mask::from_fn(w, h, |x, y| small(x, y) || large(x, y)));
    let ops = Operators::new(&domain);
    let mut rng = Pcg64::seed_from_u64(19);
    let mut eq = NormalEquations::new(&domain);
    for k in 0..domain.len() {
        let (x, y) = domain.pixel(k);
        let (Some(dx), Some(dy)) = (ops.dx(k), ops.dy(k)) else {
            continue;
        };
        if small(x, y) {
            let psi = (14.0 - y as f64).atan2(x as f64 - 20.0);
            eq.add(&dx.combine(psi.sin(), &dy, -psi.cos()), 0.0, 1.0);
            eq.add(&dx, 0.01 * psi.cos(), 1e-3);
        } else {
            eq.add(&dx, rng.random_range(-1.0..1.0), rng.random_range(0.1..2.0));
            eq.add(&dy, rng.random_range(-1.0..1.0), rng.random_range(0.1..2.0));
        }
    }
    let double = Solver::new(Ordering::NestedDissection)
        .with_mixed_min(usize::MAX)
        .solve(&eq)
        .unwrap();
    let mut solver = Solver::new(Ordering::NestedDissection)
        .with_mixed_min(0)
        .with_floored_min(0);
    let sol = solver.solve(&eq).unwrap();
    let precisions: Vec<(usize, Precision)> = solver
        .cache
        .iter()
        .map(|c| (c.key.len() - 2, c.precision))
        .collect();
    // Each system leaves out its first (pinned) unknown.
    let unknowns = |f: &dyn Fn(usize, usize) -> bool| {
        (0..domain.len())
            .filter(|&k| {
                let (x, y) = domain.pixel(k);
                f(x, y)
            })
            .count()
            - 1
    };
    let sizes = [unknowns(&small), unknowns(&large)];
    assert_eq!(
        precisions,
        [
            (sizes[0], Precision::Double),
            (sizes[1], Precision::Floored)
        ]
    );
    assert_same_solutions(&double.z, &sol.z, "mixed precision");
}

#[test]
fn a_floored_factor_refines_to_the_true_solution() {
    // The floor (relative 1e-4, far above the membrane) changes the
    // factor, not the answer: conjugate gradients on the true system
    // remove it. A system that starts at the floored factor (as one
    // whose single-precision factor failed) keeps double precision's
    // solution.
    let mut rng = Pcg64::seed_from_u64(17);
    let (disc, rows) = disc_problem(&mut rng, 60, 60, 26.0, true);
    let eq = equations(&disc, &rows);
    let mut solver = Solver::new(Ordering::NestedDissection)
        .with_mixed_min(0)
        .with_floored_min(0);
    solver.solve(&eq).unwrap();
    solver
        .cache
        .iter_mut()
        .for_each(|c| c.precision = Precision::Floored);
    assert_precision(&mut solver, &eq, Precision::Floored);
}
