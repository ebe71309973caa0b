//! Robust bounds of a set of pixel values: the exposure of a render, the
//! range of a preview picture and the figures of `sfp inspect` ignore the
//! few brightest pixels (highlights, hot pixels) through a quantile.

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
