//! Robust bounds of a set of pixel values: the exposure of a render, the
//! range of a preview picture and the figures of `sfp inspect` ignore the
//! few brightest pixels (highlights, hot pixels) through a quantile.

use crate::{Image, Mask};

/// The `q`-quantile (0..1) of `image` over the pixels of `mask`, ignoring
/// NaN; 0 for none (the exposure of a render, the robust maximum an input
/// is scaled by).
pub fn masked_percentile(image: &Image<f32>, mask: &Mask, q: f64) -> f32 {
    let inside: Vec<f32> = image
        .data()
        .iter()
        .zip(mask.data())
        .filter(|&(_, &m)| m)
        .map(|(&v, _)| v)
        .collect();
    percentile(&inside, q)
}

/// The `q`-quantile (0..1) of `values`, ignoring NaN; 0 for no values.
pub fn percentile(values: &[f32], q: f64) -> f32 {
    let mut v: Vec<f32> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return 0.0;
    }
    let k = ((v.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    let (_, kth, _) = v.select_nth_unstable_by(k, f32::total_cmp);
    *kth
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_mask_counts() {
        // 0..16 in raster order; the mask keeps the odd values.
        let image = Image::from_fn(4, 4, |x, y| (y * 4 + x) as f32);
        let mask = Image::from_fn(4, 4, |x, y| (y * 4 + x) % 2 == 1);
        assert_eq!(masked_percentile(&image, &mask, 1.0), 15.0);
        assert_eq!(masked_percentile(&image, &mask, 0.0), 1.0);
        assert_eq!(
            masked_percentile(&image, &Image::new(4, 4, false), 0.5),
            0.0
        );
    }
}
