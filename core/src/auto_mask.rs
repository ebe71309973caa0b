//! The object mask of a capture from its own intensity and DoP, for one
//! object in front of an unpolarized background that fills the image
//! border. The rule:
//!
//! 1. **Intensity.** `I = s0 / 2` as a fraction of full scale is split in
//!    two by Otsu's threshold; the side holding most border pixels is the
//!    background, the other side is object.
//! 2. **DoP.** Over pixels brighter than [`LIT`] (the DoP of darker pixels
//!    is noise), the DoP is split by Otsu's threshold, at least [`MIN_DOP`];
//!    pixels above it are object when most border pixels are below it (an
//!    unpolarized background).
//! 3. The union of both, its largest 8-connected component, with its holes
//!    (background pieces that do not reach the image border) filled.
//!
//! Why both: an intensity window loses a dark glossy object on a bright
//! sheet where its highlights are as bright as the sheet, and a dark
//! object's body where it is as dark as the shadows; the object is
//! polarized there (specular reflection, and a dark body's diffuse light)
//! while the sheet is not. A bright matte object on a dark background is
//! weakly polarized, and intensity finds it.

use crate::regions::Regions;
use crate::stokes::Stokes;
use crate::{Image, Mask};
use rayon::prelude::*;
use serde_json::json;

/// Pixels darker than this fraction of full scale have no usable DoP.
pub const LIT: f64 = 0.02;

/// The DoP threshold is never below this (sensor noise alone reaches it).
pub const MIN_DOP: f64 = 0.05;

/// Bins of the histograms Otsu's threshold is found on.
const BINS: usize = 256;

/// A mask found by the rule of the module doc, with its thresholds.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoMask {
    pub mask: Mask,
    /// Intensity threshold (fraction of full scale) and whether the object
    /// is the brighter side.
    pub intensity: f64,
    pub object_brighter: bool,
    /// DoP threshold, `None` when the border is polarized (DoP not used).
    pub dop: Option<f64>,
}

impl AutoMask {
    /// The rule's figures for `meta.json`.
    pub fn to_json(&self) -> serde_json::Value {
        json!({
            "rule": "Otsu on intensity (object = the side not on the border) or on DoP of \
                     pixels above 2% of full scale (object = above, when the border is below); \
                     largest 8-connected component, holes filled",
            "intensity_threshold": self.intensity,
            "object_brighter": self.object_brighter,
            "dop_threshold": self.dop,
        })
    }
}

/// The mask of the object in `pol` (0°, 45°, 90°, 135°, codes up to
/// `full`); see the module doc.
pub fn auto_mask(pol: &[Image<u16>; 4], full: u16) -> AutoMask {
    let (w, h) = pol[0].size();
    let k = 1.0 / f64::from(full);
    let stokes: Vec<Stokes> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let v = pol.each_ref().map(|p| f64::from(p.data()[i]) * k);
            Stokes::from_four(v[0], v[1], v[2], v[3])
        })
        .collect();
    let stokes = Image::from_vec(w, h, stokes).expect("one Stokes vector per pixel");
    let intensity = stokes.map(|s| s.unpolarized());
    let dop = stokes.map(|s| (s.unpolarized() >= LIT).then(|| s.dop()));
    let border = |x: usize, y: usize| x == 0 || y == 0 || x + 1 == w || y + 1 == h;
    let border_pixels = 2 * (w + h).saturating_sub(2);
    // Share of border pixels for which `test` holds.
    let on_border = |test: &dyn Fn(usize, usize) -> bool| {
        let n = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| border(x, y) && test(x, y))
            .count();
        n as f64 / border_pixels.max(1) as f64
    };
    let t_i = otsu(intensity.data().iter().copied()).unwrap_or(0.5);
    let object_brighter = on_border(&|x, y| *intensity.get(x, y) > t_i) < 0.5;
    let t_dop = otsu(dop.data().iter().flatten().copied()).map(|t| t.max(MIN_DOP));
    let polarized = |x: usize, y: usize, t: f64| dop.get(x, y).is_some_and(|d| d > t);
    let t_dop = t_dop.filter(|&t| on_border(&|x, y| polarized(x, y, t)) < 0.5);
    let candidate = Image::from_fn(w, h, |x, y| {
        let bright = *intensity.get(x, y) > t_i;
        bright == object_brighter || t_dop.is_some_and(|t| polarized(x, y, t))
    });
    AutoMask {
        mask: fill_holes(&largest_component(&candidate)),
        intensity: t_i,
        object_brighter,
        dop: t_dop,
    }
}

/// Otsu's threshold of `values` in `[0, 1]`: the bin edge that maximizes
/// the between-class variance of a 256-bin histogram. `None` without
/// values or when all fall in one bin.
fn otsu(values: impl Iterator<Item = f64>) -> Option<f64> {
    let mut hist = [0u64; BINS];
    for v in values {
        hist[((v.clamp(0.0, 1.0) * BINS as f64) as usize).min(BINS - 1)] += 1;
    }
    let total: u64 = hist.iter().sum();
    let weighted: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &n)| i as f64 * n as f64)
        .sum();
    let (mut below, mut below_sum) = (0u64, 0.0);
    let mut best: Option<(f64, usize)> = None;
    for (i, &n) in hist.iter().enumerate().take(BINS - 1) {
        below += n;
        below_sum += i as f64 * n as f64;
        let above = total - below;
        if below == 0 || above == 0 {
            continue;
        }
        let (m0, m1) = (
            below_sum / below as f64,
            (weighted - below_sum) / above as f64,
        );
        let between = below as f64 * above as f64 * (m0 - m1).powi(2);
        if best.is_none_or(|(b, _)| between > b) {
            best = Some((between, i));
        }
    }
    best.map(|(_, i)| (i + 1) as f64 / BINS as f64)
}

/// The largest 8-connected component of `mask` (the first in raster order
/// among equals); empty when `mask` is.
fn largest_component(mask: &Mask) -> Mask {
    let regions = Regions::components(mask);
    let largest =
        (0..regions.len()).max_by_key(|&l| (regions.list[l].pixels.len(), usize::MAX - l));
    match largest {
        Some(l) => regions.mask(l),
        None => mask.clone(),
    }
}

/// `mask` with every background piece (8-connected) that does not reach the
/// image border made object.
fn fill_holes(mask: &Mask) -> Mask {
    let (w, h) = mask.size();
    let background = Regions::components(&mask.map(|&m| !m));
    let mut out = mask.clone();
    for region in &background.list {
        let reaches_border =
            region.x0 == 0 || region.y0 == 0 || region.x1 + 1 == w || region.y1 + 1 == h;
        if !reaches_border {
            for &i in &region.pixels {
                out.data_mut()[i] = true;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    /// A 96² 12-bit capture: a disc of radius 30 (its pixels by `disc`) in
    /// front of an unpolarized background of intensity `bg`, with Gaussian
    /// noise of 4 codes per image from a seeded generator.
    fn capture(bg: f64, disc: impl Fn(f64, f64) -> Stokes) -> ([Image<u16>; 4], Mask) {
        let n = 96;
        let full = 4095.0;
        let mut rng = Pcg64::seed_from_u64(7);
        let truth = Mask::from_fn(n, n, |x, y| (x as f64 - 48.0).hypot(y as f64 - 48.0) < 30.0);
        let stokes = Image::from_fn(n, n, |x, y| {
            if *truth.get(x, y) {
                disc(x as f64 - 48.0, 48.0 - y as f64)
            } else {
                Stokes::new(2.0 * bg, 0.0, 0.0)
            }
        });
        let pol = std::array::from_fn(|i| {
            let angle = crate::stokes::STANDARD_ANGLES[i];
            stokes.map(|s| {
                let v = s.through_polarizer(angle) * full + 4.0 * gauss(&mut rng);
                v.round().clamp(0.0, full) as u16
            })
        });
        (pol, truth)
    }

    /// A standard normal draw (Box–Muller).
    fn gauss(rng: &mut Pcg64) -> f64 {
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    fn errors(found: &Mask, truth: &Mask) -> usize {
        found
            .data()
            .iter()
            .zip(truth.data())
            .filter(|(a, b)| a != b)
            .count()
    }

    #[test]
    fn otsu_splits_two_levels_between_them() {
        let values = [0.2; 50].into_iter().chain([0.7; 30]);
        let t = otsu(values).unwrap();
        assert!(t > 0.2 && t <= 0.7, "{t}");
        assert_eq!(otsu([0.4; 10].into_iter()), None);
    }

    /// A dark glossy sphere on a bright unpolarized sheet: a dark body with
    /// a strongly polarized rim, and a highlight as bright as the sheet.
    /// An intensity window loses the highlight; the rule keeps the disc.
    #[test]
    fn dark_glossy_object_on_a_bright_sheet() {
        let (pol, truth) = capture(0.7, |x, y| {
            let r = x.hypot(y) / 30.0;
            let highlight = (x - 8.0).hypot(y - 8.0) < 6.0;
            let i = if highlight { 0.72 } else { 0.08 };
            Stokes::from_polarization(2.0 * i, 0.2 + 0.5 * r * r, y.atan2(x))
        });
        let found = auto_mask(&pol, 4095);
        assert!(!found.object_brighter && found.dop.is_some(), "{found:?}");
        assert_eq!(errors(&found.mask, &truth), 0);
        let window = Mask::from_fn(96, 96, |x, y| {
            let mean = pol.iter().map(|p| f64::from(*p.get(x, y))).sum::<f64>() / 4.0 / 4095.0;
            mean < 0.3
        });
        assert!(
            errors(&window, &truth) > 80,
            "the window keeps the highlight"
        );
    }

    /// A bright matte object (weak DoP) on a dark unpolarized background,
    /// whose noisy DoP must not leak into the mask.
    #[test]
    fn bright_matte_object_on_a_dark_background() {
        let (pol, truth) = capture(0.01, |x, y| {
            let r = x.hypot(y) / 30.0;
            Stokes::from_polarization(1.2, 0.1 * r * r, y.atan2(x))
        });
        let found = auto_mask(&pol, 4095);
        assert!(found.object_brighter, "{found:?}");
        assert_eq!(errors(&found.mask, &truth), 0);
    }

    #[test]
    fn holes_are_filled_and_specks_dropped() {
        let ring = Mask::from_fn(12, 12, |x, y| {
            let r = (x as f64 - 5.5).hypot(y as f64 - 5.5);
            (2.0..5.0).contains(&r) || (x, y) == (11, 0)
        });
        let filled = fill_holes(&largest_component(&ring));
        assert!(*filled.get(5, 5) && !*filled.get(11, 0));
        assert_eq!(
            filled.count(),
            Mask::from_fn(12, 12, |x, y| (x as f64 - 5.5).hypot(y as f64 - 5.5) < 5.0).count()
        );
    }
}
