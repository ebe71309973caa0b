//! Method axes: the assumptions every method of the sweep is run with, set
//! through the options the methods share.

use super::axis::{Axis, Change, number};
use crate::row::AxisValue;
use sfp_reconstruct::shared_options::validate_eta;

/// The η every method assumes: a number, or `"true"` for the view's.
pub const METHOD_ETA: Axis = Axis {
    key: "method_eta",
    old_key: None,
    meaning: "a refractive index in (1, 3], or \"true\" (the view's)",
    accepts: |v| match v {
        AxisValue::Number(x) => validate_eta(*x).is_ok(),
        AxisValue::Text(t) => t == "true",
    },
    label: "η assumed by the method",
    unit: "",
    change: Change::Method {
        option: "eta",
        set: |s, v, true_eta| {
            s.eta = match number(v) {
                Some(eta) => eta,
                None => true_eta.clone()?,
            };
            Ok(())
        },
    },
};
