//! The summary of runs over views (`sfp demo`, `sfp reconstruct DATASET`),
//! drawn from the rows and times a sweep keeps: one line per run with the
//! figures of conventions.md §4 and the time, and a per-object table of
//! means in the shape of the paper's Table 1 (`| object | method | MAE |
//! median | <11.25° | views |`, then a `mean` line per method), as
//! `summary.md` and `summary.csv`. Means only: a run over a dataset has one
//! row per view, too few for the intervals of a sweep's report.

use super::{html, stats};
use crate::csv;
use crate::row::{Row, Timing};
use serde::Serialize;
use sfp_core::metrics::Metrics;
use sfp_core::{Result, io};
use sfp_reconstruct::methods::MethodConfig;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

/// The template of a dataset's `summary.md`.
const SUMMARY: &str = include_str!("../../templates/summary.md");

/// Header of the per-run markdown table.
const RUN_HEADER: &str = "| view | method | MAE | RMSE | median | <11.25° | <22.5° | <30° | time (s) |\n\
                          |---|---|---|---|---|---|---|---|---|\n";

/// Header of the per-object markdown table.
const OBJECT_HEADER: &str = "| object | method | MAE | median | <11.25° | views |\n\
                             |---|---|---|---|---|---|\n";

/// Name of the line that averages every view of a method.
pub const MEAN_ROW: &str = "mean";

/// The reconstruction time of each row, by key.
fn seconds(timings: &[Timing]) -> HashMap<&str, f64> {
    timings
        .iter()
        .map(|t| (t.key.as_str(), t.reconstruct_seconds))
        .collect()
}

/// The per-run markdown table: figures and time of every row in order,
/// angles in degrees with two decimals, accuracies in percent with one; `—`
/// for the figures of views without ground truth and `failed` for rows that
/// failed (their messages are listed by [`markdown`]).
pub fn run_table(rows: &[Row], timings: &[Timing]) -> String {
    let seconds = seconds(timings);
    let time = |r: &Row| seconds.get(r.key.as_str()).copied().unwrap_or(f64::NAN);
    let mut table = RUN_HEADER.to_string();
    for r in rows {
        let (view, method) = (&r.view, &r.method);
        let _ = match (&r.metrics, &r.error) {
            (_, Some(_)) => writeln!(table, "| {view} | {method} | failed | | | | | | |"),
            (Some(m), None) => writeln!(
                table,
                "| {view} | {method} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {:.2} |",
                m.mae_deg,
                m.rmse_deg,
                m.median_deg,
                m.acc_11_25,
                m.acc_22_5,
                m.acc_30,
                time(r)
            ),
            (None, None) => writeln!(
                table,
                "| {view} | {method} | — | — | — | — | — | — | {:.2} |",
                time(r)
            ),
        };
    }
    table
}

/// Mean figures of one object (or of every view: `object == MEAN_ROW`) and
/// method.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectMean {
    pub object: String,
    pub method: String,
    pub mae_deg: f64,
    pub median_deg: f64,
    pub acc_11_25: f64,
    /// Views with figures averaged.
    pub views: usize,
}

/// Means over the rows with figures, per object then per method (both in
/// order of first appearance), followed by one [`MEAN_ROW`] line per method
/// over all its rows (each view counts once, so objects with more views
/// weigh more). Rows without figures (no ground truth, failed) are left
/// out; an object or method without any gets no line.
pub fn object_means(rows: &[Row]) -> Vec<ObjectMean> {
    let objects = first_appearance(rows.iter().map(|r| r.object.as_str()));
    let methods = first_appearance(rows.iter().map(|r| r.method.as_str()));
    let mut means = Vec::new();
    for object in objects.iter().map(Some).chain([None]) {
        for method in &methods {
            let figures: Vec<&Metrics> = rows
                .iter()
                .filter(|r| r.method == *method && object.is_none_or(|o| r.object == *o))
                .filter_map(|r| r.metrics.as_ref())
                .collect();
            if figures.is_empty() {
                continue;
            }
            let mean = |f: fn(&Metrics) -> f64| {
                stats::mean(&figures.iter().map(|m| f(m)).collect::<Vec<_>>())
            };
            means.push(ObjectMean {
                object: object.map_or(MEAN_ROW, |o| o).to_string(),
                method: method.to_string(),
                mae_deg: mean(|m| m.mae_deg),
                median_deg: mean(|m| m.median_deg),
                acc_11_25: mean(|m| m.acc_11_25),
                views: figures.len(),
            });
        }
    }
    means
}

fn first_appearance<'a>(names: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut seen: Vec<&str> = Vec::new();
    for name in names {
        if !seen.contains(&name) {
            seen.push(name);
        }
    }
    seen
}

/// The per-object markdown table of `means`.
pub fn object_table(means: &[ObjectMean]) -> String {
    let mut table = OBJECT_HEADER.to_string();
    for m in means {
        let _ = writeln!(
            table,
            "| {} | {} | {:.2} | {:.2} | {:.1} | {} |",
            m.object, m.method, m.mae_deg, m.median_deg, m.acc_11_25, m.views
        );
    }
    table
}

/// The [`MEAN_ROW`] lines of [`object_means`] as a markdown table (one line
/// per method), or `None` when no row has figures.
pub fn method_means_table(rows: &[Row]) -> Option<String> {
    let means: Vec<ObjectMean> = object_means(rows)
        .into_iter()
        .filter(|m| m.object == MEAN_ROW)
        .collect();
    (!means.is_empty()).then(|| object_table(&means))
}

/// What `templates/summary.md` shows.
#[derive(Serialize)]
struct Page<'a> {
    title: &'a str,
    intro: &'a str,
    mean_row: &'a str,
    runs: String,
    /// The per-object table; `None` when no row has figures.
    objects: Option<String>,
    /// `view / method: message` of every failed row.
    failed: Vec<String>,
}

/// `summary.md`: a title and `intro`, the per-run table, the per-object
/// table and the failed rows with their messages.
pub fn markdown(title: &str, intro: &str, rows: &[Row], timings: &[Timing]) -> Result<String> {
    let means = object_means(rows);
    let page = Page {
        title,
        intro,
        mean_row: MEAN_ROW,
        runs: run_table(rows, timings),
        objects: (!means.is_empty()).then(|| object_table(&means)),
        failed: rows
            .iter()
            .filter_map(|r| {
                let e = r.error.as_ref()?;
                Some(format!(
                    "{} / {}: {}",
                    r.view,
                    r.method,
                    e.replace('\n', " ")
                ))
            })
            .collect(),
    };
    html::document("summary.md", SUMMARY, &page)
}

/// `summary.csv`: one line per row; empty fields where there is no figure,
/// the message in `error` for failed rows.
pub fn csv(rows: &[Row], timings: &[Timing]) -> String {
    let seconds = seconds(timings);
    let mut text = "view,object,method,mae_deg,rmse_deg,median_deg,acc_11_25,acc_22_5,acc_30,\
                    seconds,error\n"
        .to_string();
    for r in rows {
        let figures = r.metrics.as_ref().map_or_else(
            || ",,,,,".to_string(),
            |m| {
                format!(
                    "{},{},{},{},{},{}",
                    m.mae_deg, m.rmse_deg, m.median_deg, m.acc_11_25, m.acc_22_5, m.acc_30
                )
            },
        );
        let time = match (&r.error, seconds.get(r.key.as_str())) {
            (None, Some(s)) => s.to_string(),
            _ => String::new(),
        };
        let _ = writeln!(
            text,
            "{},{},{},{figures},{time},{}",
            csv::field(&r.view),
            csv::field(&r.object),
            csv::field(&r.method),
            csv::field(r.error.as_deref().unwrap_or(""))
        );
    }
    text
}

/// Writes `out/summary.md` (titled after `dataset`) and `out/summary.csv` of
/// `methods` run over every view of `dataset`.
pub fn write_dataset(
    out: &Path,
    dataset: &Path,
    methods: &[MethodConfig],
    rows: &[Row],
    timings: &[Timing],
) -> Result<()> {
    let configs: Vec<String> = methods
        .iter()
        .map(|m| format!("`{}`", m.to_value()))
        .collect();
    let intro = format!(
        "Every view of `{}` reconstructed by each method; angular errors in degrees over the \
         ground-truth mask (conventions.md §4), time of the reconstruction alone. \
         Results in `<view>/<method>/`.\n\nMethods: {}.",
        dataset.display(),
        configs.join(", ")
    );
    let md = markdown(
        &format!("Reconstructions of {}", dataset_name(dataset)),
        &intro,
        rows,
        timings,
    )?;
    io::write_atomic(&out.join("summary.md"), md.as_bytes())?;
    io::write_atomic(&out.join("summary.csv"), csv(rows, timings).as_bytes())
}

/// The name a dataset's rows carry: its folder name (the whole path when it
/// has none).
pub fn dataset_name(dataset: &Path) -> String {
    dataset.file_name().map_or_else(
        || dataset.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metrics(mae: f64, median: f64, acc: f64) -> Metrics {
        Metrics {
            mae_deg: mae,
            rmse_deg: mae + 1.0,
            median_deg: median,
            acc_11_25: acc,
            acc_22_5: acc + 5.0,
            acc_30: acc + 10.0,
            pixels: 100,
            missing: 0,
            specular: None,
        }
    }

    fn row(
        view: &str,
        object: &str,
        method: &str,
        result: std::result::Result<Option<Metrics>, &str>,
    ) -> Row {
        let (metrics, error) = match result {
            Ok(m) => (m, None),
            Err(e) => (None, Some(e.to_string())),
        };
        Row {
            key: format!("{view}/{method}"),
            dataset: "d".into(),
            view: view.into(),
            object: object.into(),
            axes: Default::default(),
            method: method.into(),
            config: serde_json::json!({ "method": method }),
            seed: 0,
            metrics,
            error,
            view_dir: String::new(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    fn timing(r: &Row) -> Timing {
        Timing {
            key: r.key.clone(),
            method: r.method.clone(),
            pixels: 100,
            noise_seconds: 0.0,
            reconstruct_seconds: 0.5,
            overhead_seconds: 0.0,
        }
    }

    #[test]
    fn object_means_average_per_object_and_per_method() {
        let rows = vec![
            row("cup_0", "cup", "a", Ok(Some(metrics(10.0, 8.0, 40.0)))),
            row("cup_0", "cup", "b", Ok(Some(metrics(20.0, 18.0, 10.0)))),
            row("cup_1", "cup", "a", Ok(Some(metrics(14.0, 12.0, 60.0)))),
            row("cup_1", "cup", "b", Err("boom")),
            row("vase_0", "vase", "a", Ok(Some(metrics(30.0, 20.0, 20.0)))),
            row("vase_0", "vase", "b", Ok(Some(metrics(5.0, 4.0, 90.0)))),
            // No ground truth: timings only, left out of the means.
            row("real_0", "real", "a", Ok(None)),
            row("real_0", "real", "b", Ok(None)),
        ];
        let timings: Vec<Timing> = rows
            .iter()
            .filter(|r| r.error.is_none())
            .map(timing)
            .collect();
        let means = object_means(&rows);
        let line = |o: &str, m: &str| {
            means
                .iter()
                .find(|r| r.object == o && r.method == m)
                .unwrap_or_else(|| panic!("no line {o}/{m}"))
        };
        let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-12, "{a} != {b}");
        // cup/a: (10 + 14)/2, (8 + 12)/2, (40 + 60)/2 over 2 views.
        let r = line("cup", "a");
        close(r.mae_deg, 12.0);
        close(r.median_deg, 10.0);
        close(r.acc_11_25, 50.0);
        assert_eq!(r.views, 2);
        // cup/b: the failed view is left out.
        let r = line("cup", "b");
        close(r.mae_deg, 20.0);
        assert_eq!(r.views, 1);
        // mean/a: (10 + 14 + 30)/3 = 18, (8 + 12 + 20)/3, (40 + 60 + 20)/3 = 40.
        let r = line(MEAN_ROW, "a");
        close(r.mae_deg, 18.0);
        close(r.median_deg, 40.0 / 3.0);
        close(r.acc_11_25, 40.0);
        assert_eq!(r.views, 3);
        // mean/b: (20 + 5)/2, (18 + 4)/2, (10 + 90)/2.
        let r = line(MEAN_ROW, "b");
        close(r.mae_deg, 12.5);
        close(r.median_deg, 11.0);
        close(r.acc_11_25, 50.0);
        assert_eq!(r.views, 2);
        // Objects in order, the mean lines last; none for the object without figures.
        let order: Vec<(&str, &str)> = means
            .iter()
            .map(|r| (r.object.as_str(), r.method.as_str()))
            .collect();
        assert_eq!(
            order,
            [
                ("cup", "a"),
                ("cup", "b"),
                ("vase", "a"),
                ("vase", "b"),
                ("mean", "a"),
                ("mean", "b")
            ]
        );

        let md = markdown("t", "intro", &rows, &timings).unwrap();
        assert!(
            md.contains("| mean | a | 18.00 | 13.33 | 40.0 | 3 |"),
            "{md}"
        );
        assert!(md.contains("| cup_0 | a | 10.00 | 11.00 |"), "{md}");
        assert!(md.contains("| real_0 | a | — |"), "{md}");
        assert!(md.contains("| cup_1 | b | failed | |"), "{md}");
        assert!(md.contains("- cup_1 / b: boom"), "{md}");
        let csv = csv(&rows, &timings);
        assert_eq!(csv.lines().count(), 1 + rows.len());
        assert!(csv.contains("cup_1,cup,b,,,,,,,,boom\n"), "{csv}");
        assert!(csv.contains("real_0,real,a,,,,,,,0.5,\n"), "{csv}");
    }

    #[test]
    fn a_summary_without_ground_truth_lists_the_failed_runs_last() {
        let rows = vec![
            row("v_0", "v", "a", Ok(None)),
            row("v_0", "v", "b", Err("no\nlight")),
        ];
        let md = markdown("t", "intro", &rows, &[timing(&rows[0])]).unwrap();
        assert_eq!(
            md,
            "# t\n\nintro\n\n## Runs\n\n\
             | view | method | MAE | RMSE | median | <11.25° | <22.5° | <30° | time (s) |\n\
             |---|---|---|---|---|---|---|---|---|\n\
             | v_0 | a | — | — | — | — | — | — | 0.50 |\n\
             | v_0 | b | failed | | | | | | |\n\
             \n## Per object\n\nMeans over the views with ground truth; `mean` averages every \
             such view of a method.\n\n\
             No view has ground truth.\n\
             \n## Failed runs\n\n\
             - v_0 / b: no light\n"
        );
    }
}
