//! What every method reads: unpolarized intensity `I_un`, DoP `ρ` and AoP `ψ`
//! (conventions.md §2) over the object mask, plus per-pixel reliability.
//!
//! Bad data is handled here once, so methods can assume finite values:
//! pixels with a non-finite `I_un`, `ρ` or `ψ` leave the mask (fallback,
//! counted in [`Input::dropped_nonfinite`]); an empty mask or images without
//! light are errors. Nearly dark pixels (attached or cast shadow) stay in the
//! mask but are flagged in [`Input::dark`]: their intensity says nothing
//! reliable about shading, and with noise it pulls the surface badly.
//!
//! Pixels with no usable data at all (saturated, unlit, non-finite) are
//! counted once here for every method ([`Unusable`], recorded in
//! `run.json`); a view where no mask pixel is usable is refused.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sfp_core::capture::pattern_check;
use sfp_core::fresnel::{diffuse_dop_max, diffuse_zenith};
use sfp_core::percentile::masked_percentile;
use sfp_core::stokes::Polarimetry;
use sfp_core::view::ViewInput;
use sfp_core::{Error, Image, Mask, Result};

/// Pixels with `I_un` below this fraction of the robust maximum count as dark.
pub const DEFAULT_DARK_FRACTION: f64 = 0.03;

/// Pixels with `I_un` at or below this fraction of the robust maximum carry
/// no measurable polarization (a zero signal has no DoP or AoP).
pub const UNLIT_FRACTION: f64 = 0.005;

/// Above this share of unusable mask pixels ([`Unusable::share`]) the
/// result says little about the surface: `sfp reconstruct` warns.
pub const UNUSABLE_WARN_SHARE: f64 = 0.2;

/// Percentile of `I_un` inside the mask used as the robust maximum (ignores a
/// few hot or specular pixels).
const ROBUST_MAX_PERCENTILE: f64 = 0.99;

/// Polarimetric input of one view, validated.
#[derive(Clone, Debug)]
pub struct Input {
    /// Unpolarized intensity `I_un`, in sensor units.
    pub intensity: Image<f32>,
    /// Degree of linear polarization `ρ` in `[0, 1]`.
    pub dop: Image<f32>,
    /// Angle of polarization `ψ` in `[0, π)`.
    pub aop: Image<f32>,
    /// Object pixels with finite data.
    pub mask: Mask,
    /// Mask pixels darker than `dark_fraction · intensity_scale`: shading
    /// there is unreliable.
    pub dark: Mask,
    /// Mask pixels at or below [`UNLIT_FRACTION`] of the robust maximum
    /// (attached or cast shadow): their DoP and AoP are meaningless. A subset
    /// of `dark`.
    pub unlit: Mask,
    /// Mask pixels with a polarizer image at the sensor's full scale
    /// (clipped: DoP and AoP are wrong). Known only from a view's codes
    /// ([`Input::from_view`]); empty for an input made of float images.
    pub saturated: Mask,
    /// Robust maximum of `I_un` inside the mask (99th percentile), > 0.
    pub intensity_scale: f64,
    /// Mask pixels removed because their data was NaN or infinite.
    pub dropped_nonfinite: usize,
}

impl Input {
    /// Validates `pol` with the default dark threshold. Without a mask, the
    /// object is every pixel brighter than the dark threshold (a real capture
    /// without segmentation; background must be dark for that to work).
    pub fn new(pol: Polarimetry, mask: Option<Mask>) -> Result<Self> {
        Self::with_dark_fraction(pol, mask, DEFAULT_DARK_FRACTION)
    }

    /// From a view's `input/` folder contents (polarizer images, optional
    /// mask), with its saturated pixels flagged. Refused when no mask pixel
    /// has usable data, or when the four images are not one polarization
    /// measurement (the sum rule `sfp import` measures, `pattern_check`).
    pub fn from_view(view: &ViewInput) -> Result<Self> {
        let clipped = view.saturated();
        check_consistent(view, &clipped)?;
        let mut input = Self::new(view.polarimetry(), view.mask.clone())?;
        let (w, h) = input.size();
        input.saturated = Image::from_fn(w, h, |x, y| *input.mask.get(x, y) && *clipped.get(x, y));
        let unusable = input.unusable();
        if unusable.usable == 0 {
            return Err(Error::invalid(format!(
                "no pixel of the mask has usable data: {unusable}"
            )));
        }
        Ok(input)
    }

    /// The mask pixels whose intensity a shading law can use: above the
    /// dark threshold (`unlit` is a subset of `dark`) and not clipped.
    pub fn shaded(&self) -> Mask {
        Mask::from_fn(self.mask.width(), self.mask.height(), |x, y| {
            *self.mask.get(x, y) && !*self.dark.get(x, y) && !*self.saturated.get(x, y)
        })
    }

    /// The mask pixels without usable data, and their share of the mask.
    pub fn unusable(&self) -> Unusable {
        let bad = self
            .saturated
            .data()
            .iter()
            .zip(self.unlit.data())
            .filter(|&(&s, &u)| s || u)
            .count();
        let total = self.mask.count() + self.dropped_nonfinite;
        let usable = self.mask.count() - bad;
        Unusable {
            saturated: self.saturated.count(),
            unlit: self.unlit.count(),
            nonfinite: self.dropped_nonfinite,
            usable,
            share: 1.0 - usable as f64 / total.max(1) as f64,
        }
    }

    /// As [`Input::new`], with pixels below `dark_fraction` of the robust
    /// maximum intensity flagged dark.
    pub fn with_dark_fraction(
        pol: Polarimetry,
        mask: Option<Mask>,
        dark_fraction: f64,
    ) -> Result<Self> {
        let Polarimetry {
            intensity,
            dop,
            aop,
        } = pol;
        let size = intensity.size();
        if dop.size() != size || aop.size() != size {
            return Err(Error::invalid(
                "intensity, DoP and AoP images differ in size",
            ));
        }
        if let Some(m) = &mask
            && m.size() != size
        {
            return Err(Error::invalid(format!(
                "mask is {}×{}, images are {}×{}",
                m.width(),
                m.height(),
                size.0,
                size.1
            )));
        }
        if !(UNLIT_FRACTION..1.0).contains(&dark_fraction) {
            return Err(Error::invalid(format!(
                "dark fraction {dark_fraction} is outside [{UNLIT_FRACTION}, 1)"
            )));
        }
        // Per-pixel flags in parallel passes over the pixels: sweeps build
        // an input for every noise realisation.
        let (w, h) = size;
        let finite_at = |i: usize| {
            intensity.data()[i].is_finite()
                && dop.data()[i].is_finite()
                && aop.data()[i].is_finite()
        };
        let explicit_mask = mask.is_some();
        let given_count = mask.as_ref().map(Mask::count);
        let mut inside = mask.unwrap_or_else(|| Image::new(w, h, true));
        inside
            .data_mut()
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, m)| *m = *m && finite_at(i));
        let inside_count = inside.count();
        // Without a mask the finite pixels are the given ones.
        let dropped_nonfinite = given_count.map_or(0, |n| n - inside_count);
        if inside_count == 0 {
            return Err(Error::invalid(
                "the object mask is empty (or holds only NaN/infinite pixels)",
            ));
        }
        let intensity_scale = robust_max(&intensity, &inside);
        if intensity_scale.is_nan() || intensity_scale <= 0.0 {
            return Err(Error::invalid(
                "the images hold no light inside the mask (all intensities are zero or negative)",
            ));
        }
        let threshold = dark_fraction * intensity_scale;
        let unlit_below = UNLIT_FRACTION * intensity_scale;
        let (mut dark, mut unlit) = (Image::new(w, h, false), Image::new(w, h, false));
        inside
            .data_mut()
            .par_iter_mut()
            .zip(dark.data_mut())
            .zip(unlit.data_mut())
            .zip(intensity.data())
            .for_each(|(((inside, dark), unlit), &v)| {
                let v = f64::from(v);
                if !explicit_mask {
                    *inside = *inside && v >= threshold;
                }
                *dark = *inside && v < threshold;
                *unlit = *inside && v <= unlit_below;
            });
        Ok(Input {
            unlit,
            saturated: Image::new(w, h, false),
            intensity,
            dop,
            aop,
            mask: inside,
            dark,
            intensity_scale,
            dropped_nonfinite,
        })
    }

    /// `(width, height)` of the images.
    pub fn size(&self) -> (usize, usize) {
        self.mask.size()
    }

    /// Zenith angles `θ` from the DoP with refractive index `eta` (paper
    /// Eq. 7, corrected), and the number of mask pixels whose DoP exceeded the
    /// model's maximum and was clamped to it (θ = 90°).
    pub fn zenith(&self, eta: f64) -> (Image<f32>, usize) {
        let max = diffuse_dop_max(eta);
        let mut clamped = 0;
        let theta = Image::from_fn(self.size().0, self.size().1, |x, y| {
            if !*self.mask.get(x, y) {
                return 0.0;
            }
            let rho = f64::from(*self.dop.get(x, y));
            if rho > max {
                clamped += 1;
            }
            diffuse_zenith(rho, eta) as f32
        });
        (theta, clamped)
    }

    /// The `width × height` window at `(x0, y0)` restricted to the pixels of
    /// `region` (a mask of the window's size): a region's own input, with
    /// the whole view's intensity scale so every region reads intensities in
    /// the same units.
    pub fn crop(
        &self,
        (x0, y0, width, height): (usize, usize, usize, usize),
        region: &Mask,
    ) -> Input {
        assert_eq!(
            region.size(),
            (width, height),
            "region mask is the window's size"
        );
        let inside = |m: &Mask| {
            let cut = m.crop(x0, y0, width, height);
            Image::from_fn(width, height, |x, y| *cut.get(x, y) && *region.get(x, y))
        };
        Input {
            intensity: self.intensity.crop(x0, y0, width, height),
            dop: self.dop.crop(x0, y0, width, height),
            aop: self.aop.crop(x0, y0, width, height),
            mask: inside(&self.mask),
            dark: inside(&self.dark),
            unlit: inside(&self.unlit),
            saturated: inside(&self.saturated),
            intensity_scale: self.intensity_scale,
            dropped_nonfinite: 0,
        }
    }
}

/// Mask pixels that carry no usable data, as `run.json` records them:
/// clipped, without light, or not finite (those left the mask).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Unusable {
    /// Mask pixels with a polarizer image at full scale.
    pub saturated: usize,
    /// Mask pixels at or below [`UNLIT_FRACTION`] of the robust maximum.
    pub unlit: usize,
    /// Pixels of the given mask dropped for NaN or infinite data.
    pub nonfinite: usize,
    /// Mask pixels with none of these.
    pub usable: usize,
    /// Share of the given mask (non-finite pixels included) that is not
    /// usable, in `[0, 1]`.
    pub share: f64,
}

impl std::fmt::Display for Unusable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.1} % of the mask has no usable data ({} saturated, {} without light, {} not finite)",
            100.0 * self.share,
            self.saturated,
            self.unlit,
            self.nonfinite
        )
    }
}

/// Refuses four polarizer images that do not sum as crossed polarizers
/// (`I0 + I90 = I45 + I135`, conventions.md §2) within the noise of any
/// capture (`pattern_check::MAX_RESIDUAL`), over the pixels not `clipped`:
/// unrelated images, or a view whose files were replaced, would otherwise
/// give normals of noise without a word.
fn check_consistent(view: &ViewInput, clipped: &Mask) -> Result<()> {
    let full = view.full_scale() as u16;
    let unclipped = clipped.map(|&c| !c);
    let check = pattern_check::check(&view.pol, full, Some(&unclipped), None);
    if check.pixels == 0 || check.consistent() {
        return Ok(());
    }
    Err(Error::invalid(format!(
        "the four polarizer images are not one polarization measurement: I0 + I90 differs \
         from I45 + I135 by an RMS {:.3} of s0 over {} pixels, where a capture leaves its \
         noise only (at most {}): are they the images of one scene behind polarizers at \
         0°, 45°, 90° and 135°?",
        check.sum_rule[1],
        check.pixels,
        pattern_check::MAX_RESIDUAL
    )))
}

/// 99th percentile of the intensity over the mask.
fn robust_max(intensity: &Image<f32>, mask: &Mask) -> f64 {
    f64::from(masked_percentile(intensity, mask, ROBUST_MAX_PERCENTILE))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp of intensities 0, 1, …, 99 with constant DoP and AoP.
    fn ramp() -> Polarimetry {
        Polarimetry {
            intensity: Image::from_fn(10, 10, |x, y| (y * 10 + x) as f32),
            dop: Image::new(10, 10, 0.1),
            aop: Image::new(10, 10, 0.5),
        }
    }

    #[test]
    fn dark_and_unlit_pixels_are_flagged_not_removed() {
        let input = Input::new(ramp(), Some(Mask::new(10, 10, true))).unwrap();
        // Robust maximum: the 99th percentile of 0..=99 is 98.
        assert_eq!(input.intensity_scale, 98.0);
        // Dark: below 3 % of 98 = 2.94, i.e. intensities 0, 1, 2.
        assert_eq!(input.dark.count(), 3);
        // Unlit: at or below 0.5 % of 98 = 0.49, i.e. intensity 0.
        assert_eq!(input.unlit.count(), 1);
        assert_eq!(input.mask.count(), 100);
    }

    #[test]
    fn without_a_mask_the_object_is_the_lit_pixels() {
        let input = Input::new(ramp(), None).unwrap();
        assert_eq!(input.mask.count(), 97);
        assert_eq!(input.dark.count(), 0);
    }

    #[test]
    fn sizes_and_fractions_are_checked() {
        assert!(Input::new(ramp(), Some(Mask::new(9, 10, true))).is_err());
        assert!(Input::with_dark_fraction(ramp(), None, 1.5).is_err());
        let mut pol = ramp();
        pol.dop = Image::new(10, 9, 0.1);
        assert!(Input::new(pol, None).is_err());
    }

    #[test]
    fn zenith_clamps_and_counts() {
        let mut pol = ramp();
        *pol.dop.get_mut(4, 4) = 0.9;
        let input = Input::new(pol, Some(Mask::new(10, 10, true))).unwrap();
        let (theta, clamped) = input.zenith(1.5);
        assert_eq!(clamped, 1);
        assert!((f64::from(*theta.get(4, 4)) - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        let expected = diffuse_zenith(f64::from(0.1f32), 1.5) as f32;
        assert_eq!(*theta.get(0, 0), expected);
    }

    #[test]
    fn unrelated_images_are_refused_and_a_capture_with_noise_is_read() {
        // Four images of one ramp behind crossed polarizers, with ±2 codes of
        // noise, and the same with the 90° image replaced by an unrelated one.
        let mut state = 1u64;
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % 5
        };
        let half = |x: usize, k: u64| 20_000 + 100 * x as u64 + k;
        let captured: [Image<u16>; 4] = std::array::from_fn(|a| {
            let polarized = [300u64, 0, 0, 300][a]; // s1 = 300: I0 = I135 brighter
            Image::from_fn(32, 32, |x, _| (half(x, polarized) + noise()) as u16)
        });
        let view = |pol: [Image<u16>; 4]| ViewInput::grey(pol, 16, None);
        assert!(Input::from_view(&view(captured.clone())).is_ok());
        let mut swapped = captured;
        swapped[2] = Image::from_fn(32, 32, |_, _| (noise() * 12_000) as u16);
        let err = Input::from_view(&view(swapped)).unwrap_err().to_string();
        assert!(err.contains("I0 + I90") && err.contains("0.25"), "{err}");
    }
}
