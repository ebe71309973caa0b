//! Result tables of runs over many views: one row per (view, method) with the
//! figures of conventions.md §4 and the time, and a per-object table of means
//! in the shape of the paper's Table 1 (`| object | method | MAE | median |
//! <11.25° | views |`, then a `mean` row per method). Used by `sfp demo` and
//! by `sfp reconstruct` over a dataset.

use sfp_core::metrics::Metrics;
use std::fmt::Write as _;

/// Header of the per-run markdown table ([`push_row`] writes its rows).
pub const RUN_HEADER: &str = "| view | method | MAE | RMSE | median | <11.25° | <22.5° | <30° | time (s) |\n\
                              |---|---|---|---|---|---|---|---|---|\n";

/// Header of the per-object markdown table.
pub const OBJECT_HEADER: &str = "| object | method | MAE | median | <11.25° | views |\n\
                                 |---|---|---|---|---|---|\n";

/// Appends one markdown row of [`RUN_HEADER`]: angles in degrees with two
/// decimals, accuracies in percent with one.
pub fn push_row(table: &mut String, view: &str, method: &str, m: &Metrics, seconds: f64) {
    let _ = writeln!(
        table,
        "| {view} | {method} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {seconds:.2} |",
        m.mae_deg, m.rmse_deg, m.median_deg, m.acc_11_25, m.acc_22_5, m.acc_30
    );
}

/// What one (view, method) run gave.
#[derive(Clone, Debug, PartialEq)]
pub enum RunResult {
    /// Reconstructed in `seconds`; `metrics` when the view has ground truth.
    Done {
        metrics: Option<Metrics>,
        seconds: f64,
    },
    /// The view could not be read or reconstructed.
    Failed(String),
}

/// One (view, method) run.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// View folder name.
    pub view: String,
    /// Object the view shows (per-object table).
    pub object: String,
    pub method: String,
    pub result: RunResult,
}

impl Run {
    pub fn metrics(&self) -> Option<&Metrics> {
        match &self.result {
            RunResult::Done { metrics, .. } => metrics.as_ref(),
            RunResult::Failed(_) => None,
        }
    }
}

/// Mean figures of one object (or of every view: `object == "mean"`) and method.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectMean {
    pub object: String,
    pub method: String,
    pub mae_deg: f64,
    pub median_deg: f64,
    pub acc_11_25: f64,
    /// Views with metrics averaged.
    pub views: usize,
}

/// Name of the row that averages every view of a method.
pub const MEAN_ROW: &str = "mean";

/// Means over the views with metrics, per object then per method (both in
/// order of first appearance), followed by one [`MEAN_ROW`] row per method
/// over all its views (each view counts once, so objects with more views
/// weigh more). Views without metrics (no ground truth, failed) are left out;
/// an object or method without any gets no row.
pub fn object_means(runs: &[Run]) -> Vec<ObjectMean> {
    let objects = first_appearance(runs.iter().map(|r| r.object.as_str()));
    let methods = first_appearance(runs.iter().map(|r| r.method.as_str()));
    let mut rows = Vec::new();
    for object in objects.iter().map(Some).chain([None]) {
        for method in &methods {
            let selected = runs
                .iter()
                .filter(|r| r.method == *method && object.is_none_or(|o| r.object == *o));
            if let Some(mean) = mean_of(selected.filter_map(Run::metrics)) {
                rows.push(ObjectMean {
                    object: object.map_or(MEAN_ROW, |o| o).to_string(),
                    method: method.to_string(),
                    ..mean
                });
            }
        }
    }
    rows
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

fn mean_of<'a>(metrics: impl Iterator<Item = &'a Metrics>) -> Option<ObjectMean> {
    let (mut mae, mut median, mut acc, mut n) = (0.0, 0.0, 0.0, 0usize);
    for m in metrics {
        mae += m.mae_deg;
        median += m.median_deg;
        acc += m.acc_11_25;
        n += 1;
    }
    (n > 0).then(|| {
        let k = n as f64;
        ObjectMean {
            object: String::new(),
            method: String::new(),
            mae_deg: mae / k,
            median_deg: median / k,
            acc_11_25: acc / k,
            views: n,
        }
    })
}

/// The per-object markdown table of `means` (with [`OBJECT_HEADER`]).
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

/// The [`MEAN_ROW`] rows of [`object_means`] as a markdown table (one row
/// per method), or `None` when no run has figures.
pub fn method_means_table(runs: &[Run]) -> Option<String> {
    let means: Vec<ObjectMean> = object_means(runs)
        .into_iter()
        .filter(|m| m.object == MEAN_ROW)
        .collect();
    (!means.is_empty()).then(|| object_table(&means))
}

/// The per-run markdown table: figures and time of every run, `—` for the
/// figures of views without ground truth and `failed` for runs that failed
/// (their messages are listed by [`summary_markdown`]).
pub fn run_table(runs: &[Run]) -> String {
    let mut table = RUN_HEADER.to_string();
    for r in runs {
        match &r.result {
            RunResult::Done {
                metrics: Some(m),
                seconds,
            } => push_row(&mut table, &r.view, &r.method, m, *seconds),
            RunResult::Done {
                metrics: None,
                seconds,
            } => {
                let _ = writeln!(
                    table,
                    "| {} | {} | — | — | — | — | — | — | {seconds:.2} |",
                    r.view, r.method
                );
            }
            RunResult::Failed(_) => {
                let _ = writeln!(table, "| {} | {} | failed | | | | | | |", r.view, r.method);
            }
        }
    }
    table
}

/// `summary.md`: a title and `intro`, the per-run table, the per-object
/// table and the failed runs with their messages.
pub fn summary_markdown(title: &str, intro: &str, runs: &[Run]) -> String {
    let mut md = format!("# {title}\n\n{intro}\n\n## Runs\n\n{}", run_table(runs));
    let means = object_means(runs);
    let _ = write!(
        md,
        "\n## Per object\n\nMeans over the views with ground truth; `{MEAN_ROW}` averages \
         every such view of a method.\n\n"
    );
    if means.is_empty() {
        md.push_str("No view has ground truth.\n");
    } else {
        md.push_str(&object_table(&means));
    }
    let failed: Vec<_> = runs
        .iter()
        .filter_map(|r| match &r.result {
            RunResult::Failed(e) => Some((r, e)),
            RunResult::Done { .. } => None,
        })
        .collect();
    if !failed.is_empty() {
        md.push_str("\n## Failed runs\n\n");
        for (r, e) in failed {
            let _ = writeln!(md, "- {} / {}: {}", r.view, r.method, e.replace('\n', " "));
        }
    }
    md
}

/// `summary.csv`: one line per run; empty fields where there is no figure,
/// the message in `error` for failed runs.
pub fn summary_csv(runs: &[Run]) -> String {
    let mut csv = "view,object,method,mae_deg,rmse_deg,median_deg,acc_11_25,acc_22_5,acc_30,\
                   seconds,error\n"
        .to_string();
    for r in runs {
        let (figures, seconds, error) = match &r.result {
            RunResult::Done { metrics, seconds } => {
                let figures = metrics.as_ref().map_or_else(
                    || ",,,,,".to_string(),
                    |m| {
                        format!(
                            "{},{},{},{},{},{}",
                            m.mae_deg, m.rmse_deg, m.median_deg, m.acc_11_25, m.acc_22_5, m.acc_30
                        )
                    },
                );
                (figures, seconds.to_string(), "")
            }
            RunResult::Failed(e) => (",,,,,".to_string(), String::new(), e.as_str()),
        };
        let _ = writeln!(
            csv,
            "{},{},{},{figures},{seconds},{}",
            csv_field(&r.view),
            csv_field(&r.object),
            csv_field(&r.method),
            csv_field(error)
        );
    }
    csv
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
pub fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
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
        }
    }

    fn run(view: &str, object: &str, method: &str, result: RunResult) -> Run {
        Run {
            view: view.into(),
            object: object.into(),
            method: method.into(),
            result,
        }
    }

    fn done(m: Option<Metrics>) -> RunResult {
        RunResult::Done {
            metrics: m,
            seconds: 0.5,
        }
    }

    #[test]
    fn object_means_average_per_object_and_per_method() {
        let runs = vec![
            run("cup_0", "cup", "a", done(Some(metrics(10.0, 8.0, 40.0)))),
            run("cup_0", "cup", "b", done(Some(metrics(20.0, 18.0, 10.0)))),
            run("cup_1", "cup", "a", done(Some(metrics(14.0, 12.0, 60.0)))),
            run("cup_1", "cup", "b", RunResult::Failed("boom".into())),
            run("vase_0", "vase", "a", done(Some(metrics(30.0, 20.0, 20.0)))),
            run("vase_0", "vase", "b", done(Some(metrics(5.0, 4.0, 90.0)))),
            // No ground truth: timings only, left out of the means.
            run("real_0", "real", "a", done(None)),
            run("real_0", "real", "b", done(None)),
        ];
        let means = object_means(&runs);
        let row = |o: &str, m: &str| {
            means
                .iter()
                .find(|r| r.object == o && r.method == m)
                .unwrap_or_else(|| panic!("no row {o}/{m}"))
        };
        let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-12, "{a} != {b}");
        // cup/a: (10 + 14)/2, (8 + 12)/2, (40 + 60)/2 over 2 views.
        let r = row("cup", "a");
        close(r.mae_deg, 12.0);
        close(r.median_deg, 10.0);
        close(r.acc_11_25, 50.0);
        assert_eq!(r.views, 2);
        // cup/b: the failed view is left out.
        let r = row("cup", "b");
        close(r.mae_deg, 20.0);
        assert_eq!(r.views, 1);
        // mean/a: (10 + 14 + 30)/3 = 18, (8 + 12 + 20)/3, (40 + 60 + 20)/3 = 40.
        let r = row(MEAN_ROW, "a");
        close(r.mae_deg, 18.0);
        close(r.median_deg, 40.0 / 3.0);
        close(r.acc_11_25, 40.0);
        assert_eq!(r.views, 3);
        // mean/b: (20 + 5)/2, (18 + 4)/2, (10 + 90)/2.
        let r = row(MEAN_ROW, "b");
        close(r.mae_deg, 12.5);
        close(r.median_deg, 11.0);
        close(r.acc_11_25, 50.0);
        assert_eq!(r.views, 2);
        // Objects in order, the mean rows last; no row for the object without figures.
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

        let md = summary_markdown("t", "intro", &runs);
        assert!(
            md.contains("| mean | a | 18.00 | 13.33 | 40.0 | 3 |"),
            "{md}"
        );
        assert!(md.contains("| real_0 | a | — |"), "{md}");
        assert!(md.contains("- cup_1 / b: boom"), "{md}");
        let csv = summary_csv(&runs);
        assert_eq!(csv.lines().count(), 1 + runs.len());
        assert!(csv.contains("cup_1,cup,b,,,,,,,,boom\n"), "{csv}");
        assert!(csv.contains("real_0,real,a,,,,,,,0.5,\n"), "{csv}");
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("a,b \"c\""), "\"a,b \"\"c\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
    }
}
