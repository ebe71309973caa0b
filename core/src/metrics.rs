//! Angular-error metrics of conventions.md §4 (the paper's Table 1 figures).

use crate::labelling::SpecularScores;
use crate::legend::Legend;
use crate::{Error, Image, Mask, NormalMap, Result, colormap};
use serde::{Deserialize, Serialize};

/// Error given to a mask pixel where the method returned no normal.
pub const MISSING_ERROR_DEG: f64 = 90.0;

/// Summary of the angular errors over a mask.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    pub mae_deg: f64,
    pub rmse_deg: f64,
    pub median_deg: f64,
    /// Percentage of mask pixels with error below 11.25°.
    pub acc_11_25: f64,
    pub acc_22_5: f64,
    pub acc_30: f64,
    /// Mask size.
    pub pixels: usize,
    /// Mask pixels without a prediction (counted as 90° errors).
    pub missing: usize,
    /// The method's specular labelling scored against the mixture's
    /// ground truth, when both exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular: Option<SpecularScores>,
}

/// Angle in degrees between `pred` and `gt` (both normalised here), or `None`
/// when `pred` is not a usable normal (zero or non-finite).
pub fn angular_error_deg(pred: [f32; 3], gt: [f32; 3]) -> Option<f64> {
    let p = pred.map(f64::from);
    let g = gt.map(f64::from);
    let np = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let ng = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if !np.is_finite() || np == 0.0 || ng == 0.0 {
        return None;
    }
    let c = (p[0] * g[0] + p[1] * g[1] + p[2] * g[2]) / (np * ng);
    Some(c.clamp(-1.0, 1.0).acos().to_degrees())
}

/// Per-pixel angular error in degrees: NaN outside the mask, 90° where the
/// prediction is missing.
pub fn error_map(pred: &NormalMap, gt: &NormalMap, mask: &Mask) -> Result<Image<f32>> {
    if !pred.same_size(gt) || !gt.same_size(mask) {
        return Err(Error::invalid(format!(
            "size mismatch: prediction {:?}, ground truth {:?}, mask {:?}",
            pred.size(),
            gt.size(),
            mask.size()
        )));
    }
    let data = (0..mask.len())
        .map(|i| {
            if !mask.data()[i] {
                f32::NAN
            } else {
                angular_error_deg(pred.data()[i], gt.data()[i]).unwrap_or(MISSING_ERROR_DEG) as f32
            }
        })
        .collect();
    Image::from_vec(mask.width(), mask.height(), data)
}

/// Metrics of `pred` against `gt` over `mask` (conventions.md §4).
pub fn evaluate(pred: &NormalMap, gt: &NormalMap, mask: &Mask) -> Result<Metrics> {
    let map = error_map(pred, gt, mask)?;
    let mut errors: Vec<f64> = Vec::with_capacity(mask.count());
    let mut missing = 0;
    for (i, &m) in mask.data().iter().enumerate() {
        if m {
            if angular_error_deg(pred.data()[i], gt.data()[i]).is_none() {
                missing += 1;
            }
            errors.push(f64::from(map.data()[i]));
        }
    }
    summarize(&mut errors, missing)
}

/// The legend of angular-error pictures: viridis over 0–90°.
pub const ERROR_LEGEND: Legend<'static> = Legend::Bar {
    name: "angular error",
    lo: 0.0,
    hi: 90.0,
    unit: "°",
    map: colormap::viridis,
};

/// Summary statistics of a list of per-pixel errors in degrees.
pub fn summarize(errors: &mut [f64], missing: usize) -> Result<Metrics> {
    let n = errors.len();
    if n == 0 {
        return Err(Error::invalid("the mask is empty: no pixel to evaluate"));
    }
    let nf = n as f64;
    let mae = errors.iter().sum::<f64>() / nf;
    let rmse = (errors.iter().map(|e| e * e).sum::<f64>() / nf).sqrt();
    let acc = |t: f64| 100.0 * errors.iter().filter(|&&e| e < t).count() as f64 / nf;
    let (acc_11_25, acc_22_5, acc_30) = (acc(11.25), acc(22.5), acc(30.0));
    errors.sort_by(f64::total_cmp);
    let median = if n % 2 == 1 {
        errors[n / 2]
    } else {
        0.5 * (errors[n / 2 - 1] + errors[n / 2])
    };
    Ok(Metrics {
        mae_deg: mae,
        rmse_deg: rmse,
        median_deg: median,
        acc_11_25,
        acc_22_5,
        acc_30,
        pixels: n,
        missing,
        specular: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(deg: f64) -> [f32; 3] {
        let r = deg.to_radians();
        [r.sin() as f32, 0.0, r.cos() as f32]
    }

    #[test]
    fn hand_made_pairs_give_known_figures() {
        // Four mask pixels with errors 0°, 10°, 20°, 40°; one pixel outside the mask.
        let gt = Image::from_vec(5, 1, vec![unit(0.0); 5]).unwrap();
        let pred = Image::from_vec(
            5,
            1,
            vec![unit(0.0), unit(10.0), unit(-20.0), unit(40.0), unit(90.0)],
        )
        .unwrap();
        let mask = Image::from_vec(5, 1, vec![true, true, true, true, false]).unwrap();
        let m = evaluate(&pred, &gt, &mask).unwrap();
        assert!((m.mae_deg - 17.5).abs() < 1e-5, "{m:?}");
        let rmse = ((0.0 + 100.0 + 400.0 + 1600.0) / 4.0f64).sqrt();
        assert!((m.rmse_deg - rmse).abs() < 1e-4);
        assert!((m.median_deg - 15.0).abs() < 1e-5);
        assert_eq!((m.acc_11_25, m.acc_22_5, m.acc_30), (50.0, 75.0, 75.0));
        assert_eq!((m.pixels, m.missing), (4, 0));
    }

    #[test]
    fn missing_predictions_count_as_ninety_degrees() {
        let gt = Image::from_vec(2, 1, vec![unit(0.0); 2]).unwrap();
        let pred = Image::from_vec(2, 1, vec![unit(0.0), [0.0; 3]]).unwrap();
        let mask = Image::new(2, 1, true);
        let m = evaluate(&pred, &gt, &mask).unwrap();
        assert_eq!(m.missing, 1);
        assert!((m.mae_deg - 45.0).abs() < 1e-9);
        let nan = Image::from_vec(2, 1, vec![[f32::NAN; 3], unit(0.0)]).unwrap();
        assert_eq!(evaluate(&nan, &gt, &mask).unwrap().missing, 1);
    }

    #[test]
    fn opposite_and_unnormalised_normals() {
        assert!(
            (angular_error_deg([0.0, 0.0, -2.0], [0.0, 0.0, 1.0]).unwrap() - 180.0).abs() < 1e-9
        );
        assert!(
            angular_error_deg([0.0, 0.0, 5.0], [0.0, 0.0, 1.0])
                .unwrap()
                .abs()
                < 1e-9
        );
    }

    #[test]
    fn empty_mask_and_size_mismatch_are_errors() {
        let gt = Image::new(2, 2, unit(0.0));
        assert!(evaluate(&gt, &gt, &Image::new(2, 2, false)).is_err());
        assert!(evaluate(&Image::new(3, 2, unit(0.0)), &gt, &Image::new(2, 2, true)).is_err());
    }
}
