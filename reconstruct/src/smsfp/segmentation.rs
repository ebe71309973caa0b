//! Step 3 of SMSfP (module doc): the regions the later steps start from,
//! PARG's (`parg`, Algorithm 1, Eqs. 20–26) or one region per connected
//! component of the mask without it.
//!
//! PARG reads the DoP and AoP of Stokes vectors averaged over a
//! `(2 segment_smoothing + 1)²` window, twice ([`smoothed_polarization`]): on
//! single noisy pixels it stopped growing everywhere, 9,033 seeds on the
//! built-in torus instead of 1,112; a 5×5 window (421 seeds) blurred the
//! torus' inner rim into the regions on either side.

use super::guided_filter::guided_filter;
use super::parg::{PargParams, Segmentation, segment};
use crate::input::Input;
use sfp_core::regions::{OUTSIDE, Regions};
use sfp_core::stokes::{Polarimetry, Stokes};
use sfp_core::{Image, Result};

/// PARG's segmentation of `input` with `parg` (none without), its Stokes
/// vectors smoothed over `smoothing` pixels, and its regions (the mask's
/// components without PARG).
pub(super) fn segment_regions(
    input: &Input,
    parg: Option<&PargParams>,
    smoothing: usize,
) -> Result<(Option<Segmentation>, Regions)> {
    let segments = match parg {
        Some(params) => {
            let (dop, aop) = smoothed_polarization(input, smoothing);
            Some(segment(&dop, &aop, &input.mask, params)?)
        }
        None => None,
    };
    let regions = match &segments {
        Some(seg) => {
            Regions::from_labels(seg.labels.map(|&l| if l == 0 { OUTSIDE } else { l - 1 }))
        }
        None => Regions::components(&input.mask),
    };
    Ok((segments, regions))
}

/// DoP and AoP of the Stokes vectors averaged over the mask in a
/// `(2r+1)²` window (twice: the guided filter with a constant guide is the
/// masked box mean applied twice). PARG's features are differences between
/// neighbours; where the DoP is near the noise the AoP of single pixels is
/// noise, and growth stops at every pixel (built-in torus, 256²: 9,033 seeds
/// on the raw data). Averaging the Stokes vectors, not the angles, keeps the
/// π-periodicity right.
fn smoothed_polarization(input: &Input, radius: usize) -> (Image<f32>, Image<f32>) {
    if radius == 0 {
        return (input.dop.clone(), input.aop.clone());
    }
    let (w, h) = input.size();
    let ones = Image::new(w, h, 1.0f32);
    let stokes = |x: usize, y: usize| {
        Stokes::from_polarization(
            2.0 * f64::from(*input.intensity.get(x, y)),
            f64::from(*input.dop.get(x, y)),
            f64::from(*input.aop.get(x, y)),
        )
    };
    let averaged = |part: fn(&Stokes) -> f64| {
        let src = Image::from_fn(w, h, |x, y| part(&stokes(x, y)) as f32);
        guided_filter(&ones, &src, &input.mask, radius, 1.0)
    };
    let Polarimetry { dop, aop, .. } =
        Polarimetry::from_stokes(&[averaged(|s| s.s0), averaged(|s| s.s1), averaged(|s| s.s2)]);
    (dop, aop)
}
