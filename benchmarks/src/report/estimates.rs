//! The estimates table: what the methods that estimate the scene (SMSfP's
//! refractive index, every estimated light) found, against each swept
//! axis, with bootstrap intervals. Normals inherit the errors of both, so a
//! method that degrades along an axis is read here for why (issue: noise
//! makes the `η` search follow the DoP's bias, or the light drift).

use super::axes;
use super::methods::MethodInfo;
use super::stats::{Statistics, Summary, seed_of, summarize};
use super::tables::{Cell, Head, Table, TableRow};
use crate::row::{AxisValue, Estimates, Row};

/// A figure with its interval on hover; empty without values.
fn cell(s: Option<Summary>, decimals: usize) -> Cell {
    match s {
        Some(s) => Cell {
            text: format!("{:.*}", decimals, s.mean),
            title: format!(
                "n = {}, 95% CI [{:.*}, {:.*}]",
                s.n, decimals, s.lo, decimals, s.hi
            ),
            sub: format!("[{:.*}, {:.*}]", decimals, s.lo, decimals, s.hi),
            ..Cell::default()
        },
        None => Cell::default(),
    }
}

/// One table row per (swept axis, value, method with estimates): the mean
/// estimated `η`, the mean true `η`, the mean estimate's error `η̂ − η`
/// and the mean light-direction error, each over every row of that value
/// (all datasets, views, seeds and other axes); the axes and values are
/// those of the robustness plots (`Statistics::axes`). Without a swept
/// axis, one row per method. `None` when no row has estimates.
pub fn table(rows: &[Row], stats: &Statistics, methods: &[MethodInfo]) -> Option<Table> {
    let with: Vec<&Row> = rows.iter().filter(|r| r.estimates.is_some()).collect();
    if with.is_empty() {
        return None;
    }
    // (axis, value) groups: the swept axes of the robustness plots.
    let mut groups: Vec<(String, Option<AxisValue>)> = stats
        .axes
        .iter()
        .flat_map(|a| a.values.iter().map(|v| (a.axis.clone(), Some(v.clone()))))
        .collect();
    if groups.is_empty() {
        groups.push((String::new(), None));
    }
    let mut body = Vec::new();
    let mut previous_axis: Option<String> = None;
    for (axis, value) in &groups {
        for m in methods {
            let selected: Vec<&Estimates> = with
                .iter()
                .filter(|r| r.method == m.label)
                .filter(|r| value.as_ref().is_none_or(|v| r.axes.get(axis) == Some(v)))
                .filter_map(|r| r.estimates.as_ref())
                .collect();
            if selected.is_empty() {
                continue;
            }
            let value_text = value.as_ref().map(ToString::to_string).unwrap_or_default();
            let id = |what: &str| seed_of(&["estimates", axis, &value_text, &m.label, what]);
            let eta: Vec<f64> = selected.iter().filter_map(|e| e.eta).collect();
            let truth: Vec<f64> = selected.iter().filter_map(|e| e.eta_true).collect();
            let eta_error: Vec<f64> = selected
                .iter()
                .filter_map(|e| e.eta.zip(e.eta_true).map(|(a, b)| a - b))
                .collect();
            let light: Vec<f64> = selected.iter().filter_map(|e| e.light_error_deg).collect();
            body.push(TableRow {
                cells: vec![
                    Cell::text(axes::label(axis)),
                    Cell::text(&value_text),
                    Cell::text(m.display()),
                    Cell::text(selected.len().to_string()),
                    cell(summarize(&eta, id("eta")), 3),
                    cell(summarize(&truth, id("truth")), 3),
                    cell(summarize(&eta_error, id("eta_error")), 3),
                    cell(summarize(&light, id("light")), 2),
                ],
                rule: previous_axis.as_ref().is_some_and(|p| p != axis),
            });
            previous_axis = Some(axis.clone());
        }
    }
    // Without a swept axis the axis columns would stay empty: drop them.
    let swept = !stats.axes.is_empty();
    if !swept {
        for row in &mut body {
            row.cells.drain(..2);
        }
    }
    let heads = [
        "Axis",
        "Value",
        "Method",
        "Rows",
        "estimated η",
        "true η",
        "η error",
        "light error (°)",
    ];
    Some(Table {
        id: "estimates".into(),
        title: "Estimated refractive index and light".into(),
        caption: "What the methods estimated besides the normals, against each swept axis: \
                  the whole object's refractive index (SMSfP's search) and the angle between \
                  the light direction kept and the true key light's; means over every row of \
                  the value, 95% bootstrap interval below (hover for n)."
            .into(),
        header: vec![
            heads[if swept { 0 } else { 2 }..]
                .iter()
                .map(|t| Head {
                    text: t.to_string(),
                    span: 1,
                })
                .collect(),
        ],
        rows: body,
        lead: if swept { 3 } else { 1 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::methods::catalog;
    use sfp_core::metrics::Metrics;
    use std::collections::BTreeMap;

    fn table_of(rows: &[Row]) -> Option<Table> {
        let methods = catalog(rows);
        table(rows, &Statistics::new(rows, &methods, None), &methods)
    }

    fn row(method: &str, well: f64, seed: u64, estimates: Option<Estimates>) -> Row {
        Row {
            key: format!("{method}-{well}-{seed}"),
            dataset: "builtin".into(),
            view: "sphere_0".into(),
            object: "sphere".into(),
            axes: BTreeMap::from([("noise_full_well".to_string(), AxisValue::Number(well))]),
            method: method.into(),
            config: serde_json::json!({ "method": method }),
            seed,
            metrics: Some(Metrics {
                mae_deg: 10.0,
                rmse_deg: 12.0,
                median_deg: 9.0,
                acc_11_25: 50.0,
                acc_22_5: 80.0,
                acc_30: 90.0,
                pixels: 100,
                missing: 0,
                specular: None,
            }),
            estimates,
            error: None,
            exit_status: None,
            stderr_tail: None,
            view_dir: String::new(),
            pictures: None,
        }
    }

    fn estimate(eta: Option<f64>, light: f64) -> Option<Estimates> {
        Some(Estimates {
            eta,
            eta_true: Some(1.5),
            light_error_deg: Some(light),
        })
    }

    #[test]
    fn one_row_per_axis_value_and_method_with_means() {
        let rows = vec![
            row("smsfp", 1250.0, 0, estimate(Some(1.6), 10.0)),
            row("smsfp", 1250.0, 1, estimate(Some(1.8), 20.0)),
            row("smsfp", 20000.0, 0, estimate(Some(1.5), 2.0)),
            row("smith", 1250.0, 0, estimate(None, 30.0)),
            row("atkinson", 1250.0, 0, None),
        ];
        let t = table_of(&rows).expect("a table");
        // 1250: smith and smsfp; 20000: smsfp. Atkinson estimates nothing.
        assert_eq!(t.rows.len(), 3);
        let smsfp = t
            .rows
            .iter()
            .find(|r| r.cells[1].text == "1250" && r.cells[2].text == "SMSfP")
            .expect("the smsfp row at 1250");
        assert_eq!(smsfp.cells[3].text, "2");
        assert_eq!(smsfp.cells[4].text, "1.700");
        assert_eq!(smsfp.cells[6].text, "0.200");
        assert_eq!(smsfp.cells[7].text, "15.00");
        let smith = t.rows.iter().find(|r| r.cells[2].text == "Smith").unwrap();
        assert_eq!(smith.cells[4].text, "");
        assert_eq!(smith.cells[7].text, "30.00");
    }

    #[test]
    fn no_table_without_estimates() {
        let rows = vec![row("atkinson", 1250.0, 0, None)];
        assert!(table_of(&rows).is_none());
    }
}
