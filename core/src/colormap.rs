//! Colour maps for the `preview/` pictures: a perceptual map (viridis) for DoP,
//! intensity-like scalars and angular error, a cyclic map for the axial AoP,
//! and `(n + 1) / 2` for normals.

use crate::{Image, Mask};

/// Samples of the viridis map at `t = 0, 1/8, …, 1` (sRGB).
const VIRIDIS: [[f32; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Colour of pixels outside the mask.
pub const BACKGROUND: [u8; 3] = [24, 24, 24];

/// Perceptually uniform map of `t ∈ [0, 1]` (clamped; NaN gives the background).
pub fn viridis(t: f32) -> [u8; 3] {
    if t.is_nan() {
        return BACKGROUND;
    }
    let s = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f32;
    let i = (s.floor() as usize).min(VIRIDIS.len() - 2);
    let f = s - i as f32;
    let mut c = [0u8; 3];
    for (k, ck) in c.iter_mut().enumerate() {
        *ck = (VIRIDIS[i][k] * (1.0 - f) + VIRIDIS[i + 1][k] * f).round() as u8;
    }
    c
}

/// Cyclic map for an axial angle in `[0, π)`: equal colours at 0 and π, and
/// three phase-shifted sinusoids keep the brightness nearly constant so no
/// angle looks like an edge.
pub fn cyclic(angle: f32) -> [u8; 3] {
    if angle.is_nan() {
        return BACKGROUND;
    }
    let t = 2.0 * angle;
    let third = std::f32::consts::TAU / 3.0;
    let ch = |phase: f32| ((0.5 + 0.42 * (t - phase).cos()) * 255.0).round() as u8;
    [ch(0.0), ch(third), ch(2.0 * third)]
}

/// Colour of saturated pixels in the previews: a 255 and a 0 channel,
/// which no map here gives (viridis, grey, the cyclic map's channels stay
/// within 20–235), so they never read as data or as background.
pub const SATURATED: [u8; 3] = [255, 0, 255];

/// `picture` with the pixels of `pixels` painted `colour`.
pub fn mark(picture: &mut Image<[u8; 3]>, pixels: &Mask, colour: [u8; 3]) {
    for (p, _) in picture
        .data_mut()
        .iter_mut()
        .zip(pixels.data())
        .filter(|(_, m)| **m)
    {
        *p = colour;
    }
}

/// Colour of pixels too weakly polarized to have an AoP worth showing.
pub const UNPOLARIZED: [u8; 3] = [128, 128, 128];

/// DoP below which the AoP preview shows a pixel as unpolarized: about the
/// DoP that shot noise alone gives a pixel of ~10⁴ electrons (√(2/N)), and
/// the DoP of a diffuse surface (η = 1.5) within ~25° of facing the camera.
pub const UNPOLARIZED_DOP: f32 = 0.01;

/// The AoP through [`cyclic`], pixels with DoP below [`UNPOLARIZED_DOP`] in
/// [`UNPOLARIZED`] grey (their AoP is noise, not red = 0°), the background
/// outside `mask`.
pub fn aop_preview(aop: &Image<f32>, dop: &Image<f32>, mask: Option<&Mask>) -> Image<[u8; 3]> {
    Image::from_fn(aop.width(), aop.height(), |x, y| {
        if mask.is_some_and(|m| !m.get(x, y)) {
            BACKGROUND
        } else if *dop.get(x, y) < UNPOLARIZED_DOP {
            UNPOLARIZED
        } else {
            cyclic(*aop.get(x, y))
        }
    })
}

/// Normal `n` as the usual `(n + 1) / 2` RGB; a zero vector gives the background.
pub fn normal_rgb(n: [f32; 3]) -> [u8; 3] {
    if n == [0.0; 3] || n.iter().any(|v| !v.is_finite()) {
        return BACKGROUND;
    }
    n.map(|v| ((v.clamp(-1.0, 1.0) + 1.0) * 0.5 * 255.0).round() as u8)
}

/// Scalar image through `map` after scaling `[lo, hi] → [0, 1]`; pixels outside
/// `mask` get the background colour.
pub fn scalar_preview(
    img: &Image<f32>,
    mask: Option<&Mask>,
    lo: f32,
    hi: f32,
    map: fn(f32) -> [u8; 3],
) -> Image<[u8; 3]> {
    let span = if hi > lo { hi - lo } else { 1.0 };
    Image::from_fn(img.width(), img.height(), |x, y| {
        if mask.is_some_and(|m| !m.get(x, y)) {
            BACKGROUND
        } else {
            map((img.get(x, y) - lo) / span)
        }
    })
}

/// Gray ramp, for intensity pictures.
pub fn gray(t: f32) -> [u8; 3] {
    let v = (t.clamp(0.0, 1.0) * 255.0).round() as u8;
    [v; 3]
}

/// A horizontal colour bar of `map` over `t ∈ [0, 1]` from left to right,
/// `width × height` pixels: the legend of a scalar picture (e.g. the
/// angular-error maps, viridis over 0–90°).
pub fn colour_bar(width: usize, height: usize, map: fn(f32) -> [u8; 3]) -> Image<[u8; 3]> {
    let span = width.saturating_sub(1).max(1) as f32;
    Image::from_fn(width, height, |x, _| map(x as f32 / span))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cyclic_map_wraps_at_pi() {
        assert_eq!(cyclic(0.0), cyclic(std::f32::consts::PI));
        assert_ne!(cyclic(0.0), cyclic(std::f32::consts::FRAC_PI_2));
    }

    #[test]
    fn weakly_polarized_pixels_are_grey_not_red() {
        let aop = Image::new(3, 1, 0.0f32);
        let dop = Image::from_vec(3, 1, vec![0.0, 0.5, 0.5]).unwrap();
        let mask = Image::from_vec(3, 1, vec![true, true, false]).unwrap();
        let p = aop_preview(&aop, &dop, Some(&mask));
        assert_eq!(p.data(), &[UNPOLARIZED, cyclic(0.0), BACKGROUND]);
    }

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f32::NAN), BACKGROUND);
    }

    #[test]
    fn colour_bar_runs_from_low_to_high() {
        let bar = colour_bar(9, 2, viridis);
        assert_eq!(bar.size(), (9, 2));
        assert_eq!(*bar.get(0, 1), viridis(0.0));
        assert_eq!(*bar.get(4, 0), viridis(0.5));
        assert_eq!(*bar.get(8, 0), viridis(1.0));
    }

    #[test]
    fn normals_map_to_half_offset_rgb() {
        assert_eq!(normal_rgb([0.0, 0.0, 1.0]), [128, 128, 255]);
        assert_eq!(normal_rgb([0.0; 3]), BACKGROUND);
    }
}
