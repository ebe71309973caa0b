//! The specular labelling table: for each cell (dataset, axis values,
//! method) whose rows score a labelling against the mixture's ground truth
//! (`Metrics::specular`, views rendered with `gt/specular_stokes.exr` and
//! a method run with `specular = "auto"` or a mask), the two classes of
//! `core::labelling` pooled over the cell's views and seeds. Pooling sums
//! the counts before dividing, so a view without positives weighs by its
//! labelled pixels instead of adding an F1 of 1.

use super::axes;
use super::methods::MethodInfo;
use super::tables::{Cell, Head, Table, TableRow};
use crate::row::{AxisValue, Row};
use sfp_core::labelling::{LabelScores, SpecularScores};
use std::collections::BTreeMap;

/// One cell's pooled scores.
#[derive(Clone, Debug, PartialEq)]
pub struct Pooled {
    pub dataset: String,
    pub axes: BTreeMap<String, AxisValue>,
    pub method: String,
    /// Rows pooled.
    pub rows: usize,
    pub scores: SpecularScores,
}

/// Counts of one class summed over rows.
#[derive(Clone, Copy, Default)]
struct Sum {
    positives: usize,
    labelled: usize,
    true_positives: usize,
}

impl Sum {
    fn add(&mut self, s: &LabelScores) {
        self.positives += s.positives;
        self.labelled += s.labelled;
        self.true_positives += s.true_positives;
    }

    fn scores(self) -> LabelScores {
        LabelScores::from_counts(self.positives, self.labelled, self.true_positives)
    }
}

/// Every cell with scored rows, ordered by dataset, axis values, then the
/// report's method order.
pub fn pooled(rows: &[Row], methods: &[MethodInfo]) -> Vec<Pooled> {
    type Key = (String, Vec<(String, String)>, String);
    let mut cells: BTreeMap<Key, (BTreeMap<String, AxisValue>, usize, Sum, Sum)> = BTreeMap::new();
    for r in rows {
        let Some(s) = r.metrics.as_ref().and_then(|m| m.specular.as_ref()) else {
            continue;
        };
        let key = (
            r.dataset.clone(),
            r.axes
                .iter()
                .map(|(k, v)| (k.clone(), v.to_string()))
                .collect(),
            r.method.clone(),
        );
        let cell = cells
            .entry(key)
            .or_insert_with(|| (r.axes.clone(), 0, Sum::default(), Sum::default()));
        cell.1 += 1;
        cell.2.add(&s.polarization);
        cell.3.add(&s.intensity);
    }
    let rank = |label: &str| methods.iter().position(|m| m.label == label);
    let mut out: Vec<Pooled> = cells
        .into_iter()
        .map(|((dataset, _, method), (axes, rows, p, i))| Pooled {
            dataset,
            axes,
            method,
            rows,
            scores: SpecularScores {
                polarization: p.scores(),
                intensity: i.scores(),
            },
        })
        .collect();
    out.sort_by(|a, b| {
        a.dataset
            .cmp(&b.dataset)
            .then_with(|| axes::cmp_axes(&a.axes, &b.axes))
            .then_with(|| rank(&a.method).cmp(&rank(&b.method)))
    });
    out
}

/// The table of [`pooled`]; `None` when no row scores a labelling. The
/// better F1 of each class within a (dataset, axis values) group is bold.
pub fn table(rows: &[Row], methods: &[MethodInfo]) -> Option<Table> {
    let cells = pooled(rows, methods);
    if cells.is_empty() {
        return None;
    }
    let group = |c: &Pooled| (c.dataset.clone(), axes::axes_text(&c.axes));
    let mut best: BTreeMap<(String, String), (f64, f64)> = BTreeMap::new();
    for c in &cells {
        let b = best.entry(group(c)).or_insert((f64::MIN, f64::MIN));
        b.0 = b.0.max(c.scores.polarization.f1);
        b.1 = b.1.max(c.scores.intensity.f1);
    }
    let mut body = Vec::with_capacity(cells.len());
    let mut previous = None;
    for c in &cells {
        let g = group(c);
        let (bp, bi) = best[&g];
        let class = |s: &LabelScores, best: f64| {
            vec![
                Cell::text(s.positives.to_string()),
                Cell::text(s.labelled.to_string()),
                Cell::text(format!("{:.2}", s.precision)),
                Cell::text(format!("{:.2}", s.recall)),
                Cell {
                    text: format!("{:.2}", s.f1),
                    bold: s.f1 == best,
                    ..Cell::default()
                },
            ]
        };
        let mut cells_of_row = vec![
            Cell::text(&c.dataset),
            Cell::text(axes::axes_text(&c.axes)),
            Cell::text(&c.method),
            Cell::text(c.rows.to_string()),
        ];
        cells_of_row.extend(class(&c.scores.polarization, bp));
        cells_of_row.extend(class(&c.scores.intensity, bi));
        body.push(TableRow {
            cells: cells_of_row,
            rule: previous.is_some_and(|p| p != g),
        });
        previous = Some(g);
    }
    let span = |text: &str, span: usize| Head {
        text: text.into(),
        span,
    };
    let names = [
        "Dataset",
        "Axes",
        "Method",
        "Rows",
        "positives",
        "labelled",
        "precision",
        "recall",
        "F1",
        "positives",
        "labelled",
        "precision",
        "recall",
        "F1",
    ];
    Some(Table {
        id: "specular-labelling".into(),
        title: "Specular labelling".into(),
        caption: "Each method's specular labelling against the ground truth of the mixture \
                  (gt/specular_stokes.exr), over every view and seed of a cell, counts summed \
                  before dividing. Polarization class: the pixels whose AoP the method turned, \
                  against those where the specular part's linear polarization outweighs the \
                  diffuse part's. Intensity class: the pixels whose specular share of s0 the \
                  method reads above ½ (specular.exr), against those where it is. Only methods \
                  run with specular = \"auto\" or a mask label pixels."
            .into(),
        header: vec![
            vec![
                span("", 4),
                span("polarization class", 5),
                span("intensity class", 5),
            ],
            names.iter().map(|n| span(n, 1)).collect(),
        ],
        rows: body,
        lead: 3,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::methods::catalog;
    use sfp_core::metrics::Metrics;

    fn row(view: &str, method: &str, polarization: LabelScores) -> Row {
        let intensity = LabelScores::from_counts(0, polarization.labelled, 0);
        Row {
            key: format!("{view}-{method}"),
            dataset: "b".into(),
            view: view.into(),
            object: view.into(),
            axes: BTreeMap::from([("specular".to_string(), AxisValue::Number(0.5))]),
            method: method.into(),
            config: serde_json::json!({ "method": "smith", "specular": "auto" }),
            seed: 0,
            metrics: Some(Metrics {
                mae_deg: 10.0,
                rmse_deg: 12.0,
                median_deg: 9.0,
                acc_11_25: 50.0,
                acc_22_5: 80.0,
                acc_30: 90.0,
                pixels: 100,
                missing: 0,
                specular: Some(SpecularScores {
                    polarization,
                    intensity,
                }),
            }),
            error: None,
            view_dir: String::new(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    #[test]
    fn counts_are_summed_before_dividing() {
        // View a: 10 positives, 10 labelled, 5 right (F1 0.5). View b: no
        // positive, 30 labelled (F1 0). Pooled: 5 / 40 labelled right,
        // 5 / 10 found: F1 = 2·5 / (40 + 10) = 0.2, not the mean 0.25.
        let rows = vec![
            row("a", "smith", LabelScores::from_counts(10, 10, 5)),
            row("b", "smith", LabelScores::from_counts(0, 30, 0)),
        ];
        let cells = pooled(&rows, &catalog(&rows));
        assert_eq!(cells.len(), 1);
        let p = cells[0].scores.polarization;
        assert_eq!((p.positives, p.labelled, p.true_positives), (10, 40, 5));
        assert!((p.f1 - 0.2).abs() < 1e-12, "{}", p.f1);
        assert_eq!(cells[0].rows, 2);
        let t = table(&rows, &catalog(&rows)).expect("a table");
        assert_eq!(t.rows.len(), 1);
        assert_eq!(t.rows[0].cells[8].text, "0.20");
        assert!(t.rows[0].cells[8].bold);
    }

    #[test]
    fn no_table_without_scores() {
        let mut r = row("a", "smith", LabelScores::from_counts(1, 1, 1));
        r.metrics.as_mut().unwrap().specular = None;
        assert!(table(&[r.clone()], &catalog(&[r])).is_none());
    }
}
