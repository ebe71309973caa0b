//! Step 10 of SMSfP (module doc): the regions' normals put together in one
//! map, filtered where their noise calls for it.
//!
//! The filter is a guided filter (He et al., `guided_filter`) with guide
//! `I_un` in units of its robust maximum, radius `filter_radius`,
//! `ε = filter_eps`, over the whole mask (the paper smooths the region seams
//! only; over the whole mask the same filter also averages the per-pixel
//! noise while keeping intensity edges: occlusions and shadow lines). Radius
//! 2–5 and `ε` 10⁻³–10⁻¹ changed the mean MAE of the built-in views by less
//! than 0.4°. Each pixel's normal is then a blend of its own and the
//! filtered one, weighted by its noise: with `σ` the standard deviation of
//! the per-pixel normal's angle that the Stokes noise causes at the whole
//! object's `η` (`noise::normal_noise`) and `σ_a = filter_noise_deg`, the
//! filtered normal's weight is `σ² / (σ² + σ_a²)`, so noise-free data keep
//! their own normals (are not blurred) and noisy pixels take the filtered
//! ones.

use super::guided_filter::filter_normals;
use super::region::RegionState;
use crate::input::Input;
use crate::noise::{StokesNoise, normal_noise};
use crate::solver::integrate::{height_from_normals, height_from_normals_with, height_near};
use sfp_core::{Image, Mask, NormalMap, Result};

/// The guided filter's parameters (`Smsfp::filter_radius`, `filter_eps`,
/// `filter_noise_deg`).
pub(super) struct Filter {
    pub radius: usize,
    pub eps: f64,
    /// Per-pixel normal noise (degrees) at which a pixel's own and the
    /// filtered normal weigh equally.
    pub noise_deg: f64,
}

/// The regions' normals put together by [`stitch`] (`normals`), filtered
/// with `filter` (none: as they are), the noise `noise` judged at `eta`.
pub(super) fn filtered(
    input: &Input,
    normals: NormalMap,
    filter: Option<&Filter>,
    noise: &StokesNoise,
    eta: f64,
) -> NormalMap {
    let Some(filter) = filter else {
        return normals;
    };
    let guide = input
        .intensity
        .map(|&v| (f64::from(v) / input.intensity_scale) as f32);
    let filtered = filter_normals(
        &guide,
        &normals,
        &input.mask,
        None,
        filter.radius,
        filter.eps,
    );
    let sigma = normal_noise(input, noise, eta);
    let accept = filter.noise_deg.to_radians().powi(2);
    let (w, h) = input.size();
    Image::from_fn(w, h, |x, y| {
        let s2 = f64::from(*sigma.get(x, y)).powi(2);
        let t = s2 / (s2 + accept);
        let (a, b) = (normals.get(x, y), filtered.get(x, y));
        blend(a, b, t)
    })
}

/// The regions' normals (as chosen by `normals`) in one `w × h` map.
pub(super) fn stitch<'a>(
    states: &'a [RegionState],
    w: usize,
    h: usize,
    normals: impl Fn(&'a RegionState) -> &'a Vec<[f32; 3]>,
) -> NormalMap {
    let mut out = Image::new(w, h, [0.0f32; 3]);
    for s in states {
        for (k, n) in normals(s).iter().enumerate() {
            let (x, y) = s.domain.pixel(k);
            *out.get_mut(s.x0 + x, s.y0 + y) = *n;
        }
    }
    out
}

/// Masks from this many pixels on are integrated by [`height`]'s conjugate
/// gradients; smaller ones are factorised, which is then faster (analytic
/// sphere, stitching phase: 25k pixels 0.04 s factorised against 0.055 s,
/// 50k 0.09 s either way, 82k 0.17 s against 0.14 s).
const ITERATIVE_MIN: usize = 50_000;

/// The height of the stitched `normals` over `mask` (`integrate`). From
/// [`ITERATIVE_MIN`] pixels on by conjugate gradients with multigrid
/// (`integrate::height_near`), which need few iterations on SMSfP's
/// normals (1024² analytic sphere: 4; the fruit capture at 1224×1024, 28
/// regions: 28; at the integration's `TOLERANCE`), fewer than on
/// Atkinson's (19 on the 1024² sphere at the solver default):
/// stitching of the 512² and 1024² spheres 0.44 → 0.27 s and 2.3 → 1.35 s
/// when this was introduced (1.21 s at 1024² since `integrate`'s compact
/// rows).
///
/// When one region holds the whole mask, the integration's system on the
/// region's window has the same unknowns in the same order as on the whole
/// view. The conjugate gradients then start from the region's solved
/// heights, whose normals the stitched ones differ from only by the
/// per-pixel reading and the filter (residual 9% of the right-hand side's,
/// measured before `integrate`'s compact rows; 8 iterations instead of 10
/// on the 1024² sphere then); a factorisation reuses
/// the region solver's symbolic one (its fill-reducing ordering and
/// elimination structure, a fifth of a solve). Several regions start from
/// zero: their heights joined at the seams by the best constants were a
/// worse start than zero on the fruit capture (residual 13 times the
/// right-hand side's).
pub(super) fn height(
    states: &mut [RegionState],
    normals: &NormalMap,
    mask: &Mask,
) -> Result<Image<f32>> {
    let iterative = mask.count() >= ITERATIVE_MIN;
    let s = match states {
        [s] if s.domain.len() == mask.count() => s,
        _ if iterative => return height_near(normals, mask, None),
        _ => return height_from_normals(normals, mask),
    };
    let (rw, rh) = s.input.mask.size();
    let window = normals.crop(s.x0, s.y0, rw, rh);
    let part = if iterative {
        height_near(&window, &s.input.mask, Some(&s.z))?
    } else {
        height_from_normals_with(&window, &s.input.mask, &mut s.solver)?
    };
    let (w, h) = mask.size();
    let mut out = Image::new(w, h, f32::NAN);
    for y in 0..rh {
        for x in 0..rw {
            *out.get_mut(s.x0 + x, s.y0 + y) = *part.get(x, y);
        }
    }
    Ok(out)
}

/// `(1 − t) a + t b`, renormalised (`a` where the sum vanishes; zero stays
/// zero outside the mask).
fn blend(a: &[f32; 3], b: &[f32; 3], t: f64) -> [f32; 3] {
    let v: [f64; 3] = std::array::from_fn(|i| (1.0 - t) * f64::from(a[i]) + t * f64::from(b[i]));
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len > 1e-9 {
        v.map(|c| (c / len) as f32)
    } else {
        *a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blend_weighs_and_renormalises() {
        let (a, b) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        assert_eq!(blend(&a, &b, 0.0), a);
        assert_eq!(blend(&a, &b, 1.0), b);
        let half = blend(&a, &b, 0.5);
        let s = std::f32::consts::FRAC_1_SQRT_2;
        assert!((half[0] - s).abs() < 1e-6 && (half[2] - s).abs() < 1e-6);
        // Opposite normals cancel: the first stays; outside the mask, zero.
        assert_eq!(blend(&a, &[0.0, 0.0, -1.0], 0.5), a);
        assert_eq!(blend(&[0.0; 3], &[0.0; 3], 0.3), [0.0; 3]);
    }
}
