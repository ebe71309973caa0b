//! Noise axes: the sensor an exposure of the noise-free render is made
//! with.

use super::axis::{Axis, Change, number};
use crate::row::AxisValue;

pub const NOISE_FULL_WELL: Axis = Axis {
    key: "noise_full_well",
    old_key: None,
    meaning: "electrons at full scale (> 0), or \"off\" for no shot and read noise",
    accepts: |v| match v {
        AxisValue::Number(x) => *x > 0.0 && x.is_finite(),
        AxisValue::Text(t) => t == "off",
    },
    label: "full well",
    unit: "e⁻",
    change: Change::Noise(|s, v| match number(v) {
        Some(w) => {
            s.full_well = w;
            s.noise = true;
        }
        // "off", the one text value.
        None => s.noise = false,
    }),
};

pub const NOISE_READ_SIGMA: Axis = Axis {
    key: "noise_read_sigma",
    old_key: None,
    meaning: "read noise in electrons (≥ 0)",
    accepts: |v| number(v).is_some_and(|x| x >= 0.0 && x.is_finite()),
    label: "read noise σ",
    unit: "e⁻",
    change: Change::Noise(|s, v| s.read_noise = number(v).expect("checked")),
};
