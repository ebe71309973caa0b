//! Exact Poisson and Gaussian variates for the sensor model, drawn from the
//! counter-based [`Sampler`] so noise is reproducible per pixel.

use crate::sampler::Sampler;

/// Standard normal variate (Box–Muller).
pub fn gaussian(s: &mut Sampler) -> f64 {
    let u1 = 1.0 - s.next_f64(); // (0, 1]
    let u2 = s.next_f64();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Poisson variate of mean `lambda`: multiplication method below 10,
/// Hörmann's transformed rejection (PTRS, as in NumPy) above.
pub fn poisson(lambda: f64, s: &mut Sampler) -> f64 {
    if lambda <= 0.0 {
        return 0.0;
    }
    if lambda < 10.0 {
        let limit = (-lambda).exp();
        let mut k = 0.0;
        let mut p = s.next_f64();
        while p > limit {
            k += 1.0;
            p *= s.next_f64();
        }
        return k;
    }
    // `ln λ` and `ln(1/α)` are needed only by the rare slow acceptance test,
    // so they are computed there: the fast path accepts ~80% of the draws.
    let slam = lambda.sqrt();
    let b = 0.931 + 2.53 * slam;
    let a = -0.059 + 0.02483 * b;
    let invalpha = 1.1239 + 1.1328 / (b - 3.4);
    let vr = 0.9277 - 3.6224 / (b - 2.0);
    loop {
        let u = s.next_f64() - 0.5;
        let v = s.next_f64();
        let us = 0.5 - u.abs();
        let k = ((2.0 * a / us + b) * u + lambda + 0.43).floor();
        if us >= 0.07 && v <= vr {
            return k;
        }
        if k < 0.0 || (us < 0.013 && v > us) {
            continue;
        }
        if v.ln() + invalpha.ln() - (a / (us * us) + b).ln()
            <= -lambda + k * lambda.ln() - ln_gamma(k + 1.0)
        {
            return k;
        }
    }
}

/// `ln Γ(x)` for `x ≥ 1` (Stirling series after shifting to `x ≥ 7`; NumPy's
/// `random_loggam`).
fn ln_gamma(x: f64) -> f64 {
    const A: [f64; 10] = [
        8.333333333333333e-02,
        -2.777777777777778e-03,
        7.936507936507937e-04,
        -5.952380952380952e-04,
        8.417508417508418e-04,
        -1.917526917526918e-03,
        6.410_256_410_256_41e-3,
        -2.955065359477124e-02,
        1.796443723688307e-01,
        -1.39243221690590e+00,
    ];
    if x == 1.0 || x == 2.0 {
        return 0.0;
    }
    let n = if x < 7.0 { (7.0 - x).floor() } else { 0.0 };
    let mut x0 = x + n;
    let x2 = 1.0 / (x0 * x0);
    let mut g = A[9];
    for &c in A[..9].iter().rev() {
        g = g * x2 + c;
    }
    let mut gl = g / x0 + 0.5 * (2.0 * std::f64::consts::PI).ln() + (x0 - 0.5) * x0.ln() - x0;
    for _ in 0..n as u32 {
        gl -= (x0 - 1.0).ln();
        x0 -= 1.0;
    }
    gl
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Stream;

    #[test]
    fn ln_gamma_matches_factorials() {
        let mut f = 1.0f64;
        for k in 1..30 {
            f *= f64::from(k);
            assert!(
                (ln_gamma(f64::from(k) + 1.0) - f.ln()).abs() < 1e-10,
                "k={k}"
            );
        }
    }

    #[test]
    fn poisson_and_gaussian_moments() {
        let mut s = Sampler::new(11, Stream::Sensor, 0, 0, 0);
        for lambda in [0.5, 3.0, 12.0, 80.0, 20000.0] {
            let n = 100_000;
            let draws: Vec<f64> = (0..n).map(|_| poisson(lambda, &mut s)).collect();
            let mean = draws.iter().sum::<f64>() / f64::from(n);
            let var = draws.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / f64::from(n - 1);
            let se = (lambda / f64::from(n)).sqrt();
            assert!((mean - lambda).abs() < 5.0 * se, "λ={lambda} mean {mean}");
            assert!((var / lambda - 1.0).abs() < 0.03, "λ={lambda} var {var}");
        }
        let n = 100_000;
        let g: Vec<f64> = (0..n).map(|_| gaussian(&mut s)).collect();
        let mean = g.iter().sum::<f64>() / f64::from(n);
        let var = g.iter().map(|x| x * x).sum::<f64>() / f64::from(n);
        assert!(mean.abs() < 0.02 && (var - 1.0).abs() < 0.02);
    }
}
