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
use crate::integrate::{ITERATIVE_MIN, height_from_normals, height_from_normals_with};
use crate::noise::{StokesNoise, normal_noise};
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

/// The height of the stitched `normals` over `mask` (`integrate`). When one
/// region holds the whole mask, the integration's system on the region's
/// window has the same unknowns in the same order as on the whole view, and
/// the region's solver already holds its symbolic factorisation (its
/// fill-reducing ordering and elimination structure, a fifth of a solve):
/// the normals are integrated there, to the same heights, unless the
/// system is large enough for the integration's iterative solver
/// (`integrate::ITERATIVE_MIN`).
pub(super) fn height(
    states: &mut [RegionState],
    normals: &NormalMap,
    mask: &Mask,
) -> Result<Image<f32>> {
    let [s] = states else {
        return height_from_normals(normals, mask);
    };
    if s.domain.len() != mask.count() || s.domain.len() >= ITERATIVE_MIN {
        return height_from_normals(normals, mask);
    }
    let (rw, rh) = s.input.mask.size();
    let window = normals.crop(s.x0, s.y0, rw, rh);
    let part = height_from_normals_with(&window, &s.input.mask, &mut s.solver)?;
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
