//! Sensor noise in the Stokes images, and how far the DoP stands above it.
//!
//! The DoP is a magnitude, `ρ = √(s1² + s2²)/s0`: zero-mean noise in `s1` and
//! `s2` raises it on average, `E[ρ̂²] = ρ² + 2σ²/s0²` (`σ²` the variance of
//! the noise in `s1` and in `s2`). Where the true DoP is small (surfaces
//! facing the camera, `θ ≲ 30°` at `η = 1.5`) the noise makes the DoP, and
//! a refractive index fitted there comes out too high. Fits that need the
//! DoP's value (SMSfP's `η`) use only pixels whose DoP is several times
//! its noise ([`dop_snr`]). (Subtracting the bias from `ρ̂²` instead made
//! every built-in view worse: 0.5–2.7° MAE with the true `η`.)
//!
//! `σ²` is estimated from the data, so it works for any sensor: for a smooth
//! signal the discrete Laplacian `4s(p) − Σ s(neighbours)` is mostly noise,
//! with variance `20σ²`; its median square (robust to edges and fast AoP
//! turns, where the signal itself curves) is `0.455 × 20σ²` for Gaussian
//! noise. Noise grows with the signal (shot noise) over a floor (read
//! noise), so the estimate is made in [`BINS`] intensity bins of equal
//! population and fitted by `σ²(s0) = a + b·s0` with `a, b ≥ 0`.

use crate::input::Input;
use sfp_core::Image;
use sfp_core::fresnel::{diffuse_dop, diffuse_zenith};
use sfp_core::stokes::Stokes;

/// Intensity bins of the noise fit.
pub const BINS: usize = 12;

/// Fewest Laplacian samples a bin needs to count.
const MIN_BIN: usize = 50;

/// `median(χ²₁)`: the median of `r²` for a unit Gaussian `r`.
const MEDIAN_CHI2: f64 = 0.454_936;

/// Noise variance of `s1` and `s2` as a function of `s0` (intensity units of
/// the input, `s0 = 2 I_un`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StokesNoise {
    /// Floor (read noise), `a`.
    pub floor: f64,
    /// Growth per unit `s0` (shot noise), `b`.
    pub slope: f64,
}

impl StokesNoise {
    pub fn variance(&self, s0: f64) -> f64 {
        self.floor + self.slope * s0
    }

    /// Standard deviation of the DoP at `s0`: one Stokes component's noise
    /// over `s0`.
    pub fn dop_sigma(&self, s0: f64) -> f64 {
        self.variance(s0).max(0.0).sqrt() / s0
    }

    /// Standard deviation of the unpolarized intensity `I_un = s0 / 2` at
    /// `i_un`: with four polarizer images of equal noise, `s1 = I0 − I90`
    /// has twice the variance of one image and `I_un = ¼ Σ I` a quarter,
    /// so `var(I_un) = var(s1) / 8`.
    pub fn intensity_sigma(&self, i_un: f64) -> f64 {
        (self.variance(2.0 * i_un).max(0.0) / 8.0).sqrt()
    }
}

/// Estimates the noise of `input`'s `s1` and `s2` (module doc). Inputs too
/// small to fill a bin give zero noise (no correction).
pub fn stokes_noise(input: &Input) -> StokesNoise {
    let (w, h) = input.size();
    let stokes = |x: usize, y: usize| {
        let s = Stokes::from_polarization(
            2.0 * f64::from(*input.intensity.get(x, y)),
            f64::from(*input.dop.get(x, y)),
            f64::from(*input.aop.get(x, y)),
        );
        (s.s0, s.s1, s.s2)
    };
    // (s0, r² of s1, r² of s2) at interior lit pixels.
    let mut samples: Vec<(f64, f64)> = Vec::new();
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let near = [(x, y), (x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)];
            if near
                .iter()
                .any(|&(nx, ny)| !*input.mask.get(nx, ny) || *input.unlit.get(nx, ny))
            {
                continue;
            }
            let (s0, s1, s2) = stokes(x, y);
            let (mut l1, mut l2) = (4.0 * s1, 4.0 * s2);
            for &(nx, ny) in &near[1..] {
                let (_, a, b) = stokes(nx, ny);
                l1 -= a;
                l2 -= b;
            }
            samples.push((s0, l1 * l1));
            samples.push((s0, l2 * l2));
        }
    }
    if samples.len() < BINS * MIN_BIN {
        return StokesNoise {
            floor: 0.0,
            slope: 0.0,
        };
    }
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Per bin: mean s0 and the robust σ².
    let per_bin = samples.len() / BINS;
    let points: Vec<(f64, f64)> = samples
        .chunks(per_bin)
        .filter(|c| c.len() >= MIN_BIN)
        .map(|c| {
            let s0 = c.iter().map(|s| s.0).sum::<f64>() / c.len() as f64;
            let mut r2: Vec<f64> = c.iter().map(|s| s.1).collect();
            let mid = r2.len() / 2;
            let (_, median, _) = r2.select_nth_unstable_by(mid, f64::total_cmp);
            (s0, *median / (MEDIAN_CHI2 * 20.0))
        })
        .collect();
    fit_line(&points)
}

/// Least-squares `σ² = a + b s0` with `a, b ≥ 0` (a negative coefficient is
/// dropped and the other refitted alone).
fn fit_line(points: &[(f64, f64)]) -> StokesNoise {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for &(x, y) in points {
        sxx += (x - mx) * (x - mx);
        sxy += (x - mx) * (y - my);
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let floor = my - slope * mx;
    if slope >= 0.0 && floor >= 0.0 {
        return StokesNoise { floor, slope };
    }
    if slope < 0.0 {
        return StokesNoise {
            floor: my.max(0.0),
            slope: 0.0,
        };
    }
    // Floor negative: a line through the origin.
    let sxx0: f64 = points.iter().map(|p| p.0 * p.0).sum();
    let sxy0: f64 = points.iter().map(|p| p.0 * p.1).sum();
    StokesNoise {
        floor: 0.0,
        slope: if sxx0 > 0.0 {
            (sxy0 / sxx0).max(0.0)
        } else {
            0.0
        },
    }
}

/// Signal-to-noise ratio of the DoP at every pixel, `ρ̂ s0 / σ(s0)`: the
/// measured polarized magnitude over the noise of one Stokes component.
/// Pure noise gives a Rayleigh-distributed ratio with median ≈ 1.18; where it
/// is a few times that, the DoP is measured and not made by the noise.
/// Zero outside the mask and where `s0 ≤ 0`; infinite without noise.
pub fn dop_snr(input: &Input, noise: &StokesNoise) -> Image<f32> {
    let (w, h) = input.size();
    Image::from_fn(w, h, |x, y| {
        let s0 = 2.0 * f64::from(*input.intensity.get(x, y));
        if !*input.mask.get(x, y) || s0 <= 0.0 {
            return 0.0;
        }
        let rho = f64::from(*input.dop.get(x, y));
        (rho * s0 / noise.variance(s0).sqrt()) as f32
    })
}

/// Weight of an azimuth row whose DoP stands `snr` times above its noise:
/// `σ_a² / (σ_a² + σ_ψ²)`, `σ_ψ = 1 / (2·snr)` the AoP's noise (radians)
/// and `σ_a = model_deg` the AoP's error that is not noise (the surface's
/// own departures from the model), at which the two weigh equally. A row
/// `sin ψ z_x − cos ψ z_y = 0` whose `ψ` is noise pulls the gradient towards
/// zero whatever the surface, so uniform weights flatten a dim surface
/// (issue: noise-aware SMSfP, full well 1250 e⁻: built-in objects 21° too
/// flat on average, the azimuth right to 3°). 1 without noise, 0 where the
/// DoP is zero.
pub fn azimuth_weight(snr: f64, model_deg: f64) -> f64 {
    if !snr.is_finite() {
        return 1.0;
    }
    model_weight(model_deg.to_radians(), 0.5 / snr.max(f64::MIN_POSITIVE))
}

/// `σ_m² / (σ_m² + σ²)`: the weight of a measurement with noise `σ` against
/// the model's own error `σ_m`, equal where the two are.
pub fn model_weight(model: f64, sigma: f64) -> f64 {
    model * model / (model * model + sigma * sigma)
}

/// Standard deviation (radians) of the angle of a per-pixel polarization
/// normal (zenith from the DoP at `eta`, azimuth from the AoP) caused by the
/// Stokes noise: the DoP's noise `σ_ρ = σ(s0)/s0` moves the zenith by
/// `σ_ρ / |∂ρ_d/∂θ|` and the AoP by `σ_ρ / 2ρ`, which tilts the normal by
/// `sin θ` times that; capped at π/2. Zero outside the mask.
pub fn normal_noise(input: &Input, noise: &StokesNoise, eta: f64) -> Image<f32> {
    let (w, h) = input.size();
    let cap = std::f64::consts::FRAC_PI_2;
    Image::from_fn(w, h, |x, y| {
        let s0 = 2.0 * f64::from(*input.intensity.get(x, y));
        if !*input.mask.get(x, y) || s0 <= 0.0 {
            return 0.0;
        }
        let sigma = noise.dop_sigma(s0);
        if sigma == 0.0 {
            return 0.0;
        }
        let rho = f64::from(*input.dop.get(x, y));
        let theta = diffuse_zenith(rho, eta).min(cap - 1e-3);
        let step = 1e-3;
        let slope = (diffuse_dop(theta + step, eta) - diffuse_dop(theta, eta)) / step;
        let zenith = (sigma / slope.max(1e-9)).min(cap);
        let azimuth = (sigma / (2.0 * rho.max(sigma))).min(cap) * theta.sin();
        zenith.hypot(azimuth).min(cap) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuth_weight_halves_where_noise_equals_the_model_error() {
        // σ_ψ = 1 / (2 snr) = 5° at snr = 1 / (2 · 5° in radians).
        let snr = 0.5 / 5f64.to_radians();
        assert!((azimuth_weight(snr, 5.0) - 0.5).abs() < 1e-12);
        assert_eq!(azimuth_weight(f64::INFINITY, 5.0), 1.0);
        assert_eq!(azimuth_weight(0.0, 5.0), 0.0);
        assert!(azimuth_weight(100.0, 5.0) > 0.99);
        assert!(azimuth_weight(1.0, 5.0) < 0.04);
    }
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;
    use sfp_core::stokes::Polarimetry;
    use sfp_core::{Image, Mask};

    /// A unit normal draw (Box–Muller).
    fn normal(rng: &mut Pcg64) -> f64 {
        let u: f64 = rng.random_range(1e-12..1.0);
        let v: f64 = rng.random_range(0.0..1.0);
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// A smooth, weakly polarized ramp with Stokes noise of variance
    /// `a + b s0` added to `s1` and `s2`.
    fn noisy(a: f64, b: f64, seed: u64, gain: f32) -> (Input, Image<f32>) {
        let (w, h) = (96, 96);
        let mut rng = Pcg64::seed_from_u64(seed);
        let s0 = Image::from_fn(w, h, |x, _| 200.0 + 30.0 * x as f32);
        let rho = Image::from_fn(w, h, |_, y| gain * (0.01 + 0.002 * y as f32));
        let (mut i, mut d, mut p) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..w * h {
            let s = f64::from(s0.data()[k]);
            let sd = (a + b * s).sqrt();
            let s1 = s * f64::from(rho.data()[k]) + sd * normal(&mut rng);
            let s2 = sd * normal(&mut rng);
            i.push((s / 2.0) as f32);
            d.push(((s1 * s1 + s2 * s2).sqrt() / s) as f32);
            p.push((0.5 * s2.atan2(s1)).rem_euclid(std::f64::consts::PI) as f32);
        }
        let pol = Polarimetry {
            intensity: Image::from_vec(w, h, i).unwrap(),
            dop: Image::from_vec(w, h, d).unwrap(),
            aop: Image::from_vec(w, h, p).unwrap(),
        };
        (Input::new(pol, Some(Mask::new(w, h, true))).unwrap(), rho)
    }

    #[test]
    fn noise_model_is_recovered() {
        let (input, _) = noisy(4.0, 0.5, 1, 1.0);
        let model = stokes_noise(&input);
        for s0 in [400.0, 1500.0, 3000.0] {
            let (got, want) = (model.variance(s0), 4.0 + 0.5 * s0);
            assert!(
                (got / want - 1.0).abs() < 0.15,
                "s0 {s0}: σ² {got} vs {want}"
            );
        }
    }

    #[test]
    fn snr_of_pure_noise_is_rayleigh_and_grows_with_the_signal() {
        let (noise_only, _) = noisy(4.0, 0.5, 2, 0.0);
        let model = stokes_noise(&noise_only);
        let mut snr = dop_snr(&noise_only, &model).into_vec();
        let mid = snr.len() / 2;
        let (_, median, _) = snr.select_nth_unstable_by(mid, f32::total_cmp);
        assert!(
            (*median - 1.177).abs() < 0.1,
            "median SNR of noise {median}"
        );
        let (signal, _) = noisy(4.0, 0.5, 2, 1.0);
        let snr = dop_snr(&signal, &stokes_noise(&signal));
        // ρ = 0.2 at the last row, s0 ≈ 3000 at the last column: ≈ 15.
        let corner = *snr.get(95, 95);
        assert!((10.0..20.0).contains(&corner), "SNR {corner}");
    }

    #[test]
    fn normal_noise_follows_the_dop_slope() {
        let (input, _) = noisy(4.0, 0.5, 4, 1.0);
        let model = stokes_noise(&input);
        let angle = normal_noise(&input, &model, 1.5);
        // By hand at one pixel: σ_ρ, the zenith slope, the AoP term.
        let (x, y) = (60, 80);
        let s0 = 2.0 * f64::from(*input.intensity.get(x, y));
        let sigma = model.variance(s0).sqrt() / s0;
        let rho = f64::from(*input.dop.get(x, y));
        let t = diffuse_zenith(rho, 1.5);
        let slope = (diffuse_dop(t + 1e-6, 1.5) - diffuse_dop(t - 1e-6, 1.5)) / 2e-6;
        let want = (sigma / slope).hypot(sigma / (2.0 * rho) * t.sin());
        let got = f64::from(*angle.get(x, y));
        assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
        // Stronger polarization, less angular noise.
        assert!(angle.get(60, 95) < angle.get(60, 20));
    }

    #[test]
    fn noise_free_data_have_no_noise() {
        let (input, _) = noisy(0.0, 0.0, 3, 1.0);
        let model = stokes_noise(&input);
        assert!(model.variance(1000.0) < 1e-6, "{model:?}");
    }
}
