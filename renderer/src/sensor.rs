//! The camera sensor: exposure, shot and read noise, quantization, clipping
//! (the optional division-of-focal-plane mosaic is `sfp_core::capture::mosaic`).

use crate::sampler::{SamplerKey, Stream};
use crate::scene::SensorDesc;
use crate::variates::{gaussian, poisson};
use rayon::prelude::*;
use sfp_core::percentile::masked_percentile;
use sfp_core::{Image, Mask};

/// Sensor codes of the four polarizer images and the exposure used.
pub struct Exposed {
    pub pol: [Image<u16>; 4],
    /// Codes per unit of rendered radiance (`s0`).
    pub scale: f64,
}

/// Ideal polarizer intensities at 0°, 45°, 90°, 135°:
/// `I(ϑ) = ½(s0 + s1 cos2ϑ + s2 sin2ϑ)` with exact trigonometric values.
#[inline]
pub fn polarizer_intensities(s0: f64, s1: f64, s2: f64) -> [f64; 4] {
    [
        0.5 * (s0 + s1),
        0.5 * (s0 + s2),
        0.5 * (s0 - s1),
        0.5 * (s0 - s2),
    ]
}

/// Exposes, adds noise and quantizes. The exposure maps the
/// `exposure_percentile` quantile of `s0` inside `mask` to `exposure_level`
/// of full scale. Noise draws come from `(seed, view, pixel, channel)`.
pub fn expose(
    desc: &SensorDesc,
    stokes: &[Image<f32>; 3],
    mask: &Mask,
    seed: u64,
    view: u64,
) -> Exposed {
    expose_where(desc, stokes, mask, seed, view, false)
}

/// [`expose`] with noise drawn inside `mask` only: the same codes as
/// [`expose`] there (draws are keyed per pixel), noise-free codes outside.
/// For many noise realisations of one render (sweeps) whose methods read
/// only the object's pixels: the background's draws would cost as much as
/// the object's.
pub fn expose_inside(
    desc: &SensorDesc,
    stokes: &[Image<f32>; 3],
    mask: &Mask,
    seed: u64,
    view: u64,
) -> Exposed {
    expose_where(desc, stokes, mask, seed, view, true)
}

fn expose_where(
    desc: &SensorDesc,
    stokes: &[Image<f32>; 3],
    mask: &Mask,
    seed: u64,
    view: u64,
    inside_only: bool,
) -> Exposed {
    let (w, h) = stokes[0].size();
    let scale = exposure_scale(desc, &stokes[0], mask);
    let key = SamplerKey::new(seed, Stream::Sensor, view);
    let mut pol: [Image<u16>; 4] = std::array::from_fn(|_| Image::new(w, h, 0));
    let [p0, p1, p2, p3] = &mut pol;
    p0.data_mut()
        .par_iter_mut()
        .zip(p1.data_mut())
        .zip(p2.data_mut())
        .zip(p3.data_mut())
        .enumerate()
        .for_each(|(i, (((o0, o1), o2), o3))| {
            let s = [0, 1, 2].map(|k| f64::from(stokes[k].data()[i]) * scale);
            let noise = desc.noise && (!inside_only || mask.data()[i]);
            let codes = pixel_codes(desc, s, noise.then(|| key.pixel(i as u64)), 0);
            for (o, v) in [o0, o1, o2, o3].into_iter().zip(codes) {
                *o = v;
            }
        });
    Exposed { pol, scale }
}

/// Codes of the four polarizer images of each colour channel (R, G, B) and
/// the exposure used.
pub struct ExposedColour {
    pub rgb: [Image<[u16; 3]>; 4],
    /// Codes per unit of rendered radiance, one for all channels.
    pub scale: f64,
}

/// [`expose`] of a colour render: one exposure for the three channels, set
/// by each pixel's brightest channel's `s0` (so no channel clips where a
/// grey render of it would not), so the channels keep their ratios; each
/// channel's noise has draws of its own.
pub fn expose_colour(
    desc: &SensorDesc,
    channels: &[[Image<f32>; 3]; 3],
    mask: &Mask,
    seed: u64,
    view: u64,
) -> ExposedColour {
    let (w, h) = channels[0][0].size();
    let brightest = Image::from_fn(w, h, |x, y| {
        channels
            .iter()
            .map(|c| *c[0].get(x, y))
            .fold(f32::NEG_INFINITY, f32::max)
    });
    let scale = exposure_scale(desc, &brightest, mask);
    let key = SamplerKey::new(seed, Stream::Sensor, view);
    let codes: Vec<[[u16; 4]; 3]> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            std::array::from_fn(|c| {
                let s = channels[c]
                    .each_ref()
                    .map(|k| f64::from(k.data()[i]) * scale);
                let pixel = desc.noise.then(|| key.pixel(i as u64));
                pixel_codes(desc, s, pixel, 4 * c as u64)
            })
        })
        .collect();
    let rgb = std::array::from_fn(|k| {
        Image::from_vec(w, h, codes.iter().map(|p| p.map(|c| c[k])).collect())
            .expect("size matches")
    });
    ExposedColour { rgb, scale }
}

/// Codes per unit of radiance: the `exposure_percentile` quantile of `s0`
/// inside `mask` at `exposure_level` of full scale.
fn exposure_scale(desc: &SensorDesc, s0: &Image<f32>, mask: &Mask) -> f64 {
    let full = f64::from((1u32 << desc.bits) - 1);
    let reference = f64::from(masked_percentile(s0, mask, desc.exposure_percentile));
    if reference > 0.0 {
        desc.exposure_level * full / reference
    } else {
        0.0
    }
}

/// The four polarizer codes of one pixel's Stokes vector `s` (in codes),
/// with shot and read noise drawn from `pixel`'s samplers `first..first + 4`
/// when given.
fn pixel_codes(desc: &SensorDesc, s: [f64; 3], pixel: Option<SamplerKey>, first: u64) -> [u16; 4] {
    let full = f64::from((1u32 << desc.bits) - 1);
    let electrons_per_code = desc.full_well / full;
    let intensities = polarizer_intensities(s[0], s[1], s[2]);
    std::array::from_fn(|c| {
        let mut v = intensities[c].max(0.0);
        if let Some(pixel) = pixel {
            let mut s = pixel.sampler(first + c as u64);
            let e = poisson(v * electrons_per_code, &mut s) + desc.read_noise * gaussian(&mut s);
            v = e / electrons_per_code;
        }
        v.round().clamp(0.0, full) as u16
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(w: usize, h: usize, s: [f32; 3]) -> [Image<f32>; 3] {
        s.map(|v| Image::new(w, h, v))
    }

    #[test]
    fn noiseless_exposure_quantizes_exactly() {
        let desc = SensorDesc {
            noise: false,
            exposure_percentile: 1.0,
            exposure_level: 0.5,
            ..SensorDesc::default()
        };
        let st = uniform(4, 3, [2.0, 0.4, -0.2]);
        let e = expose(&desc, &st, &Mask::new(4, 3, true), 1, 0);
        let k = 0.5 * 65535.0 / 2.0;
        let expect = polarizer_intensities(2.0 * k, 0.4 * k, -0.2 * k).map(|v| v.round() as u16);
        for (img, want) in e.pol.iter().zip(expect) {
            assert!(img.data().iter().all(|&v| v == want));
        }
    }

    #[test]
    fn noise_has_shot_plus_read_variance_and_clips() {
        let desc = SensorDesc {
            bits: 12,
            exposure_percentile: 1.0,
            exposure_level: 0.5,
            full_well: 10000.0,
            read_noise: 5.0,
            ..SensorDesc::default()
        };
        let (w, h) = (200, 200);
        let st = uniform(w, h, [1.0, 0.0, 0.0]);
        let e = expose(&desc, &st, &Mask::new(w, h, true), 3, 0);
        let full = 4095.0;
        let mean_code = 0.25 * full; // I = s0/2 at half of full scale
        let epc = 10000.0 / full;
        let expect_var = (mean_code * epc + 25.0) / (epc * epc) + 1.0 / 12.0;
        let v: Vec<f64> = e.pol[0].data().iter().map(|&x| f64::from(x)).collect();
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
        assert!((m - mean_code).abs() < 0.1, "{m}");
        assert!(
            (var / expect_var - 1.0).abs() < 0.05,
            "{var} vs {expect_var}"
        );
        let bright = expose(
            &SensorDesc {
                exposure_level: 3.0,
                ..desc
            },
            &st,
            &Mask::new(w, h, true),
            3,
            0,
        );
        assert!(bright.pol[0].data().iter().all(|&x| x == 4095));
    }

    #[test]
    fn noise_inside_the_mask_only_matches_the_full_exposure_there() {
        let desc = SensorDesc {
            full_well: 1000.0,
            ..SensorDesc::default()
        };
        let st = uniform(16, 8, [1.0, 0.3, -0.1]);
        let mask = Image::from_fn(16, 8, |x, y| (x + y) % 3 == 0);
        let full = expose(&desc, &st, &mask, 5, 2);
        let inside = expose_inside(&desc, &st, &mask, 5, 2);
        let quiet = expose(
            &SensorDesc {
                noise: false,
                ..desc.clone()
            },
            &st,
            &mask,
            5,
            2,
        );
        assert_eq!(full.scale, inside.scale);
        for c in 0..4 {
            for (i, &m) in mask.data().iter().enumerate() {
                let want = if m { &full } else { &quiet };
                assert_eq!(inside.pol[c].data()[i], want.pol[c].data()[i], "{c} {i}");
            }
        }
        assert_ne!(full.pol[0], quiet.pol[0]);
    }
}
