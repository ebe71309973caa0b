//! Names, units and order of the swept axes (`Row::axes`) as the report
//! shows them. The names and units are the axes' own (`sweep::axes`; an
//! old key labelled as its axis); axes the registry does not know are shown
//! by their raw name, without a unit.

use crate::row::AxisValue;
use crate::sweep::axes;
use std::cmp::Ordering;
use std::collections::BTreeMap;

/// How an axis is labelled: a readable name and its unit (empty: unitless
/// or text).
pub fn describe(axis: &str) -> (&str, &'static str) {
    match axes::named(axis) {
        Some((a, _)) => (a.label, a.unit),
        None => (axis, ""),
    }
}

/// Axis label with its unit in parentheses, e.g. `light elevation (°)`.
pub fn label(axis: &str) -> String {
    match describe(axis) {
        (name, "") => name.to_string(),
        (name, unit) => format!("{name} ({unit})"),
    }
}

/// Total order of axis values: numbers by value before names by text.
pub fn cmp_value(a: &AxisValue, b: &AxisValue) -> Ordering {
    match (a, b) {
        (AxisValue::Number(x), AxisValue::Number(y)) => x.total_cmp(y),
        (AxisValue::Number(_), AxisValue::Text(_)) => Ordering::Less,
        (AxisValue::Text(_), AxisValue::Number(_)) => Ordering::Greater,
        (AxisValue::Text(x), AxisValue::Text(y)) => x.cmp(y),
    }
}

/// Total order of axis-value maps (by axis name, then value; a missing axis
/// sorts first).
pub fn cmp_axes(a: &BTreeMap<String, AxisValue>, b: &BTreeMap<String, AxisValue>) -> Ordering {
    let names = |m: &BTreeMap<String, AxisValue>| m.keys().cloned().collect::<Vec<_>>();
    let mut all = names(a);
    all.extend(names(b));
    all.sort();
    all.dedup();
    for name in all {
        let ord = match (a.get(&name), b.get(&name)) {
            (Some(x), Some(y)) => cmp_value(x, y),
            (None, Some(_)) => Ordering::Less,
            (Some(_), None) => Ordering::Greater,
            (None, None) => Ordering::Equal,
        };
        if ord != Ordering::Equal {
            return ord;
        }
    }
    Ordering::Equal
}

/// `name=value` pairs, comma-separated (`—` for no axes).
pub fn axes_text(axes: &BTreeMap<String, AxisValue>) -> String {
    if axes.is_empty() {
        return "—".to_string();
    }
    axes.iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_axes_have_units_and_unknown_ones_keep_their_name() {
        assert_eq!(label("light_elevation_deg"), "light elevation (°)");
        assert_eq!(label("noise_read_sigma"), "read noise σ (e⁻)");
        assert_eq!(label("wobble"), "wobble");
        // Rows of sweeps written before the rename keep their label.
        assert_eq!(label("specular"), "specular weight");
    }

    #[test]
    fn values_order_numbers_before_names() {
        let n = |v| AxisValue::Number(v);
        let t = |s: &str| AxisValue::Text(s.into());
        let mut v = vec![t("on"), n(2.0), t("off"), n(-1.0)];
        v.sort_by(cmp_value);
        assert_eq!(v, vec![n(-1.0), n(2.0), t("off"), t("on")]);
        assert_eq!(n(20000.0).to_string(), "20000");
        assert_eq!(n(1.5).to_string(), "1.5");
    }
}
