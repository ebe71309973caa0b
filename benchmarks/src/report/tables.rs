//! The report's tables as data ([`Table`]: header rows with spans, body
//! rows of cells with a bold flag), rendered to HTML by the template and to
//! markdown by [`Table::markdown`]. Angles in degrees with two decimals,
//! accuracies in percent with one; the best value of a column (within a
//! group of rows that compare methods on the same inputs) is bold.

use super::axes;
use super::methods::MethodInfo;
use super::stats::{self, CellStats, MIN_PAIRS, Metric, Paired, Pool, Statistics, Summary, fixed};
use crate::csv;
use crate::row::{AxisValue, Row, Timing};
use serde::Serialize;
use std::collections::BTreeMap;

/// A header cell spanning `span` columns.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Head {
    pub text: String,
    pub span: usize,
}

/// A body cell; `title` is shown on hover in the HTML (e.g. the interval),
/// `sub` on a second, smaller line (after the text in markdown).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Cell {
    pub text: String,
    pub bold: bool,
    pub title: String,
    pub sub: String,
}

impl Cell {
    pub fn text(text: impl Into<String>) -> Cell {
        Cell {
            text: text.into(),
            ..Cell::default()
        }
    }
}

/// A body row; `rule` draws a line above it (a new group).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TableRow {
    pub cells: Vec<Cell>,
    pub rule: bool,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Table {
    /// Anchor in the HTML.
    pub id: String,
    pub title: String,
    pub caption: String,
    /// Header rows, top to bottom; the last one names every column.
    pub header: Vec<Vec<Head>>,
    pub rows: Vec<TableRow>,
    /// Leading columns that hold names (left-aligned), not figures.
    pub lead: usize,
}

impl Table {
    /// The table as GitHub markdown: one header line whose column names
    /// carry the top group's name and a middle group's unit
    /// (`A · MAE (°)`), `**bold**` best values.
    pub fn markdown(&self) -> String {
        let columns = self
            .header
            .last()
            .map_or(0, |h| h.iter().map(|c| c.span).sum());
        let mut names: Vec<Vec<String>> = vec![Vec::new(); columns];
        let levels = self.header.len();
        for (l, level) in self.header.iter().enumerate() {
            let mut col = 0;
            for head in level {
                for name in names.iter_mut().skip(col).take(head.span) {
                    let middle = l > 0 && l + 1 < levels;
                    if head.text.is_empty() {
                        continue;
                    }
                    if !middle {
                        name.push(head.text.clone());
                    } else if let Some(i) = head.text.rfind(" (") {
                        // A middle group contributes its unit only.
                        name.push(head.text[i..].trim().to_string());
                    }
                }
                col += head.span;
            }
        }
        // The unit follows the column name.
        for name in names.iter_mut().filter(|n| n.len() == 3) {
            name.swap(1, 2);
            let unit = name.pop().expect("three parts");
            name[1] = format!("{} {unit}", name[1]);
        }
        let esc = |s: &str| s.replace('|', "\\|");
        let mut md = String::new();
        md.push('|');
        for n in &names {
            md.push_str(&format!(" {} |", esc(&n.join(" · "))));
        }
        md.push_str("\n|");
        md.push_str(&"---|".repeat(columns));
        md.push('\n');
        for row in &self.rows {
            md.push('|');
            for c in &row.cells {
                let text = if c.bold && !c.text.is_empty() {
                    format!("**{}**", esc(&c.text))
                } else {
                    esc(&c.text)
                };
                if c.sub.is_empty() {
                    md.push_str(&format!(" {text} |"));
                } else {
                    md.push_str(&format!(" {text} {} |", esc(&c.sub)));
                }
            }
            md.push('\n');
        }
        md
    }
}

fn heads(texts: &[&str]) -> Vec<Head> {
    texts
        .iter()
        .map(|t| Head {
            text: t.to_string(),
            span: 1,
        })
        .collect()
}

/// The two header rows over the five figures of the paper: `angular error
/// (°)` over MAE and RMSE, `pixel accuracy (%)` over the three thresholds.
fn paper_heads() -> (Vec<Head>, Vec<Head>) {
    (
        vec![
            Head {
                text: "angular error (°)".into(),
                span: 2,
            },
            Head {
                text: "pixel accuracy (%)".into(),
                span: 3,
            },
        ],
        heads(&["MAE", "RMSE", "<11.25°", "<22.5°", "<30°"]),
    )
}

/// A figure cell: the mean, and its interval on hover.
fn figure(metric: Metric, s: Option<&Summary>) -> Cell {
    match s {
        Some(s) => Cell {
            text: metric.format(s.mean),
            bold: false,
            title: format!(
                "n = {}, 95% CI [{}, {}]",
                s.n,
                metric.format(s.lo),
                metric.format(s.hi)
            ),
            sub: String::new(),
        },
        None => Cell::text("—"),
    }
}

/// Makes bold, in each listed column, the best value among `rows` (all of
/// them on a tie). `values[r][k]` is the value of row `r` in column
/// `columns[k].0` for metric `columns[k].1`; NaN for none.
fn mark_best(
    table_rows: &mut [TableRow],
    rows: &[usize],
    columns: &[(usize, Metric)],
    values: &[Vec<f64>],
) {
    for (k, &(col, metric)) in columns.iter().enumerate() {
        let best = rows
            .iter()
            .zip(values)
            .map(|(_, v)| v[k])
            .filter(|v| v.is_finite())
            .reduce(|a, b| if metric.better(b, a) { b } else { a });
        if let Some(best) = best {
            // Compare as printed, so equal-looking values are both bold.
            let shown = metric.format(best);
            for (&r, v) in rows.iter().zip(values) {
                if v[k].is_finite() && metric.format(v[k]) == shown {
                    table_rows[r].cells[col].bold = true;
                }
            }
        }
    }
}

/// Table 1 of the paper: per dataset, MAE, RMSE and the three accuracies of
/// every full method (ablations are in [`ablation_table`]), pooled over every
/// swept condition; best per column bold.
pub fn paper_table(stats: &Statistics, methods: &[MethodInfo]) -> Table {
    let datasets = &stats.datasets;
    let methods: Vec<&MethodInfo> = methods.iter().filter(|m| !m.is_ablation()).collect();
    let (groups, names) = paper_heads();
    let mut header = vec![
        vec![Head {
            text: "Method".into(),
            span: 1,
        }],
        vec![Head {
            text: String::new(),
            span: 1,
        }],
        heads(&[""]),
    ];
    for d in datasets {
        header[0].push(Head {
            text: format!("Dataset {d}"),
            span: 5,
        });
        header[1].extend(groups.iter().cloned());
        header[2].extend(names.iter().cloned());
    }
    let mut table_rows = Vec::new();
    let mut values = Vec::new();
    for m in &methods {
        let mut cells = vec![Cell::text(m.display())];
        let mut vals = Vec::new();
        for d in datasets {
            let figures = stats.get(&Pool::Dataset {
                dataset: d.clone(),
                method: m.label.clone(),
            });
            for metric in Metric::PAPER {
                let s = figures.and_then(|f| f.get(metric));
                cells.push(figure(metric, s));
                vals.push(s.map_or(f64::NAN, |s| s.mean));
            }
        }
        table_rows.push(TableRow { cells, rule: false });
        values.push(vals);
    }
    let columns: Vec<(usize, Metric)> = (0..datasets.len())
        .flat_map(|d| {
            Metric::PAPER
                .iter()
                .enumerate()
                .map(move |(k, &m)| (1 + 5 * d + k, m))
        })
        .collect();
    let all: Vec<usize> = (0..table_rows.len()).collect();
    mark_best(&mut table_rows, &all, &columns, &values);
    Table {
        id: "table1".into(),
        title: "Methods per dataset (the paper's Table 1)".into(),
        caption: "Means over every row with figures of a method in a dataset (every view, \
                  seed and swept condition; each method saw the same inputs). Best per column \
                  in bold; hover a figure for its row count and 95% bootstrap interval."
            .into(),
        header,
        rows: table_rows,
        lead: 1,
    }
}

/// Figures of the six metrics, the best bold within each (dataset, object):
/// one row per object and method label.
pub fn object_table(stats: &Statistics, methods: &[MethodInfo]) -> Table {
    let mut header = heads(&["Dataset", "Object", "Method"]);
    header.extend(Metric::ALL.iter().map(|m| Head {
        text: format!("{} ({})", m.name(), m.unit()),
        span: 1,
    }));
    header.push(Head {
        text: "rows".into(),
        span: 1,
    });
    let mut table_rows = Vec::new();
    let columns: Vec<(usize, Metric)> = Metric::ALL
        .iter()
        .enumerate()
        .map(|(k, &m)| (3 + k, m))
        .collect();
    for (d, o) in &stats.objects {
        let mut group = Vec::new();
        let mut values = Vec::new();
        for m in methods {
            let pool = Pool::Object {
                dataset: d.clone(),
                object: o.clone(),
                method: m.label.clone(),
            };
            let Some(figures) = stats.get(&pool) else {
                continue;
            };
            let mut cells = vec![Cell::text(d), Cell::text(o), Cell::text(m.display())];
            let mut vals = Vec::new();
            for metric in Metric::ALL {
                let s = figures.get(metric);
                cells.push(figure(metric, s));
                vals.push(s.map_or(f64::NAN, |s| s.mean));
            }
            cells.push(Cell::text(format!(
                "{}/{}",
                figures.with_figures(),
                figures.rows
            )));
            group.push(table_rows.len());
            table_rows.push(TableRow {
                cells,
                rule: values.is_empty(),
            });
            values.push(vals);
        }
        mark_best(&mut table_rows, &group, &columns, &values);
    }
    Table {
        id: "objects".into(),
        title: "Per object".into(),
        caption: "Means over the rows of each object (every view of it, seed and swept \
                  condition); \"rows\" counts rows with figures out of all rows. Best per object \
                  in bold."
            .into(),
        header: vec![header],
        rows: table_rows,
        lead: 3,
    }
}

/// Table 2 of the paper: per object (and the average over every row), the
/// five figures of each SMSfP ablation and of the full `reference`; best
/// per row and figure bold. `None` without ablations or reference.
pub fn ablation_table(stats: &Statistics) -> Option<Table> {
    let ablation = stats.ablation.as_ref()?;
    let (groups, objects) = (&ablation.groups, &ablation.objects);
    let many_datasets = stats.datasets.len() > 1;
    let (sub, names) = paper_heads();
    let mut header = vec![heads(&["Object"]), heads(&[""]), heads(&[""])];
    for g in groups {
        let text = if g.is_ablation() {
            format!("{} ({})", g.label, g.ablation_text())
        } else {
            format!("{} (w/ all steps)", g.display())
        };
        header[0].push(Head { text, span: 5 });
        header[1].extend(sub.iter().cloned());
        header[2].extend(names.iter().cloned());
    }
    let columns_of = |g: usize| -> Vec<(usize, Metric)> {
        Metric::PAPER
            .iter()
            .enumerate()
            .map(|(k, &m)| (1 + 5 * g + k, m))
            .collect()
    };
    let mut table_rows = Vec::new();
    let lines = objects
        .iter()
        .map(|(d, o)| (Some((d.as_str(), o.as_str())), false))
        .chain([(None, true)]);
    for (object, rule) in lines {
        let name = match object {
            Some((d, o)) if many_datasets => format!("{o} ({d})"),
            Some((_, o)) => o.to_string(),
            None => "Average".to_string(),
        };
        let mut cells = vec![Cell::text(name)];
        let mut per_group = Vec::new();
        for g in groups {
            let pool = match object {
                Some((d, o)) => Pool::AblationObject {
                    dataset: d.to_string(),
                    object: o.to_string(),
                    method: g.label.clone(),
                },
                None => Pool::AblationAverage {
                    method: g.label.clone(),
                },
            };
            let figures = stats.get(&pool);
            let mut vals = Vec::new();
            for metric in Metric::PAPER {
                let s = figures.and_then(|f| f.get(metric));
                cells.push(figure(metric, s));
                vals.push(s.map_or(f64::NAN, |s| s.mean));
            }
            per_group.push(vals);
        }
        let r = table_rows.len();
        table_rows.push(TableRow { cells, rule });
        // Best across the groups, figure by figure.
        for (k, &metric) in Metric::PAPER.iter().enumerate() {
            let cols: Vec<usize> = (0..groups.len()).map(|g| columns_of(g)[k].0).collect();
            let vals: Vec<f64> = per_group.iter().map(|v| v[k]).collect();
            let best = vals
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .reduce(|a, b| if metric.better(b, a) { b } else { a });
            if let Some(best) = best {
                for (c, v) in cols.iter().zip(&vals) {
                    if v.is_finite() && metric.format(*v) == metric.format(best) {
                        table_rows[r].cells[*c].bold = true;
                    }
                }
            }
        }
    }
    Some(Table {
        id: "table2".into(),
        title: "Ablation (the paper's Table 2)".into(),
        caption: "SMSfP with one or more steps switched off, against the full method, per \
                  object; \"Average\" is the mean over every row of a label. Best per row and \
                  figure in bold."
            .into(),
        header,
        rows: table_rows,
        lead: 1,
    })
}

/// One line per cell (dataset, axis values, method): rows, failures and
/// rows without ground truth, and every metric as `mean ± sd [95% CI]`;
/// best mean per (dataset, axis values) in bold.
pub fn cell_table(stats: &Statistics) -> Table {
    let names = &stats.axis_names;
    let mut header = heads(&["Dataset"]);
    header.extend(names.iter().map(|a| Head {
        text: axes::label(a),
        span: 1,
    }));
    header.extend(heads(&["Method", "rows", "failed", "no GT"]));
    let first = header.len();
    header.extend(Metric::ALL.iter().map(|m| Head {
        text: format!("{} ({})", m.name(), m.unit()),
        span: 1,
    }));
    let columns: Vec<(usize, Metric)> = Metric::ALL
        .iter()
        .enumerate()
        .map(|(k, &m)| (first + k, m))
        .collect();
    let mut table_rows = Vec::new();
    let mut group: Vec<usize> = Vec::new();
    let mut values: Vec<Vec<f64>> = Vec::new();
    let mut last: Option<(&str, &BTreeMap<String, AxisValue>)> = None;
    for c in &stats.cells {
        let here = (c.dataset.as_str(), &c.axes);
        let new_group = last != Some(here);
        if new_group {
            mark_best(&mut table_rows, &group, &columns, &values);
            group.clear();
            values.clear();
        }
        last = Some(here);
        let mut cells_row = vec![Cell::text(&c.dataset)];
        cells_row.extend(
            names
                .iter()
                .map(|a| Cell::text(c.axes.get(a).map_or("—".into(), AxisValue::to_string))),
        );
        cells_row.push(Cell::text(&c.display));
        cells_row.push(Cell::text(c.figures.rows.to_string()));
        cells_row.push(Cell::text(c.figures.failed.to_string()));
        cells_row.push(Cell::text(c.figures.no_truth.to_string()));
        let mut vals = Vec::new();
        for metric in Metric::ALL {
            let s = c.figures.get(metric);
            cells_row.push(match s {
                Some(s) => Cell {
                    text: format!(
                        "{} ± {}",
                        metric.format(s.mean),
                        s.sd.map_or("—".into(), |sd| metric.format(sd)),
                    ),
                    bold: false,
                    title: format!("n = {}", s.n),
                    sub: format!("[{}, {}]", metric.format(s.lo), metric.format(s.hi)),
                },
                None => Cell::text("—"),
            });
            vals.push(s.map_or(f64::NAN, |s| s.mean));
        }
        group.push(table_rows.len());
        table_rows.push(TableRow {
            cells: cells_row,
            rule: new_group,
        });
        values.push(vals);
    }
    mark_best(&mut table_rows, &group, &columns, &values);
    Table {
        id: "cells".into(),
        title: "Every cell".into(),
        caption: format!(
            "A cell is one (dataset, axis values, method); its rows differ by view and noise \
             seed. Figures: mean ± standard deviation [95% percentile-bootstrap interval of the \
             mean, {} resamples of the rows, seeded]. Failed rows and rows without ground \
             truth are counted, not averaged. Best mean per condition in bold.",
            stats::RESAMPLES
        ),
        header: vec![header],
        rows: table_rows,
        lead: names.len() + 2,
    }
}

/// `stats.csv`: one line per cell and metric (empty statistics for cells
/// without figures).
pub fn cells_csv(cells: &[CellStats]) -> String {
    let mut csv =
        "dataset,axes,method,metric,n,mean,sd,ci_low,ci_high,rows,failed,no_gt\n".to_string();
    for c in cells {
        let ax = csv::field(&axes::axes_text(&c.axes));
        for metric in Metric::ALL {
            let figures = match c.figures.get(metric) {
                Some(s) => format!(
                    "{},{},{},{},{}",
                    s.n,
                    s.mean,
                    s.sd.map_or(String::new(), |v| v.to_string()),
                    s.lo,
                    s.hi
                ),
                None => "0,,,,".to_string(),
            };
            csv.push_str(&format!(
                "{},{ax},{},{},{figures},{},{},{}\n",
                csv::field(&c.dataset),
                csv::field(&c.method),
                metric.key(),
                c.figures.rows,
                c.figures.failed,
                c.figures.no_truth
            ));
        }
    }
    csv
}

/// Paired comparisons: one line per (dataset, comparison, metric).
pub fn paired_table(paired: &[Paired], methods: &[MethodInfo]) -> Table {
    let display = |label: &str| {
        methods
            .iter()
            .find(|m| m.label == label)
            .map_or(label.to_string(), MethodInfo::display)
    };
    let header = heads(&[
        "Dataset",
        "Comparison",
        "Figure",
        "pairs",
        "mean difference",
        "95% CI",
        "wins / ties / losses",
        "win rate",
    ]);
    let mut rows = Vec::new();
    let mut last = None;
    for p in paired {
        let here = (&p.dataset, &p.slice, &p.reference, &p.other);
        let unit = p.metric.unit();
        let ci_excludes_zero = p.has_interval() && (p.lo > 0.0 || p.hi < 0.0);
        let dataset = match &p.slice {
            Some(slice) => format!("{} · {slice}", p.dataset),
            None => p.dataset.clone(),
        };
        rows.push(TableRow {
            cells: vec![
                Cell::text(dataset),
                Cell::text(format!("{} − {}", display(&p.reference), display(&p.other))),
                Cell::text(format!("{} ({unit})", p.metric.name())),
                Cell::text(p.n.to_string()),
                Cell {
                    text: fixed(p.mean, p.metric.decimals(), true),
                    bold: ci_excludes_zero,
                    title: if ci_excludes_zero {
                        "the 95% interval excludes 0".into()
                    } else {
                        String::new()
                    },
                    sub: String::new(),
                },
                if p.has_interval() {
                    Cell::text(format!(
                        "[{}, {}]",
                        p.metric.format(p.lo),
                        p.metric.format(p.hi)
                    ))
                } else {
                    Cell {
                        title: format!("fewer than {MIN_PAIRS} pairs: no interval"),
                        ..Cell::text("n/a")
                    }
                },
                Cell::text(format!("{} / {} / {}", p.wins, p.ties, p.losses)),
                Cell::text(format!("{:.1}%", p.win_rate())),
            ],
            rule: last.is_some_and(|l| l != here),
        });
        last = Some(here);
    }
    Table {
        id: "paired".into(),
        title: "Paired comparisons".into(),
        caption: "Differences on identical inputs (same dataset, view, axis values and noise \
                  seed): A − B per pair, its mean and 95% bootstrap interval (bold when the \
                  interval excludes 0; n/a below 5 pairs); a win is a pair where A has the lower error or the \
                  higher accuracy, a tie an equal figure."
            .into(),
        header: vec![header],
        rows,
        lead: 3,
    }
}

/// [`paired_table`] of the per-axis-value comparisons
/// (`Statistics::paired_by_axis`).
pub fn paired_by_axis_table(paired: &[Paired], methods: &[MethodInfo]) -> Table {
    Table {
        id: "paired-by-axis".into(),
        title: "Paired comparisons per axis value".into(),
        caption: "The MAE comparisons of the table above over the inputs that share one value \
                  of a swept axis (dataset · axis=value): what pooling over the axis hides."
            .into(),
        ..paired_table(paired, methods)
    }
}

/// Time per view of each method label, from `timings.csv`.
pub fn timing_table(timings: &[Timing], methods: &[MethodInfo]) -> Table {
    let header = heads(&[
        "Method",
        "rows",
        "pixels (mean)",
        "reconstruct s/view (mean)",
        "median",
        "max",
        "noise s (mean)",
        "other s (mean)",
        "total s",
    ]);
    let mut labels: Vec<String> = methods.iter().map(|m| m.label.clone()).collect();
    for t in timings {
        if !labels.contains(&t.method) {
            labels.push(t.method.clone());
        }
    }
    let mut rows = Vec::new();
    for label in labels {
        let ts: Vec<&Timing> = timings.iter().filter(|t| t.method == label).collect();
        if ts.is_empty() {
            continue;
        }
        let n = ts.len() as f64;
        let mut rec: Vec<f64> = ts.iter().map(|t| t.reconstruct_seconds).collect();
        rec.sort_by(f64::total_cmp);
        let mean = |f: fn(&Timing) -> f64| ts.iter().map(|t| f(t)).sum::<f64>() / n;
        let total: f64 = ts
            .iter()
            .map(|t| t.noise_seconds + t.reconstruct_seconds + t.overhead_seconds)
            .sum();
        let display = methods
            .iter()
            .find(|m| m.label == label)
            .map_or(label.clone(), MethodInfo::display);
        rows.push(TableRow {
            cells: vec![
                Cell::text(display),
                Cell::text(ts.len().to_string()),
                Cell::text(format!("{:.0}", mean(|t| t.pixels as f64))),
                Cell::text(format!("{:.3}", mean(|t| t.reconstruct_seconds))),
                Cell::text(format!("{:.3}", stats::quantile(&rec, 0.5))),
                Cell::text(format!("{:.3}", rec.last().copied().unwrap_or(0.0))),
                Cell::text(format!("{:.3}", mean(|t| t.noise_seconds))),
                Cell::text(format!("{:.3}", mean(|t| t.overhead_seconds))),
                Cell::text(format!("{total:.1}")),
            ],
            rule: false,
        });
    }
    Table {
        id: "timings".into(),
        title: "Time per view".into(),
        caption: "Wall time of each row (one view, one seed), seconds: the reconstruction \
                  alone, exposing the noise-free view with the row's seed, and everything \
                  else (metrics, writing). These depend on the machine and its load, unlike \
                  every other table."
            .into(),
        header: vec![header],
        rows,
        lead: 1,
    }
}

/// Rows without figures: failed ones with their message, and those of views
/// without ground truth (at most `limit` lines).
pub fn missing_table(rows: &[Row], methods: &[MethodInfo], limit: usize) -> Option<Table> {
    let mut missing: Vec<&Row> = rows.iter().filter(|r| r.metrics.is_none()).collect();
    if missing.is_empty() {
        return None;
    }
    let rank = |r: &Row| methods.iter().position(|m| m.label == r.method);
    missing.sort_by(|a, b| {
        (&a.dataset, &a.view)
            .cmp(&(&b.dataset, &b.view))
            .then_with(|| axes::cmp_axes(&a.axes, &b.axes))
            .then((rank(a), a.seed).cmp(&(rank(b), b.seed)))
    });
    let total = missing.len();
    let rows: Vec<TableRow> = missing
        .into_iter()
        .take(limit)
        .map(|r| TableRow {
            cells: vec![
                Cell::text(&r.dataset),
                Cell::text(&r.view),
                Cell::text(axes::axes_text(&r.axes)),
                Cell::text(&r.method),
                Cell::text(r.seed.to_string()),
                Cell::text(match (&r.error, r.stderr_tail.as_deref()) {
                    (Some(e), None) => format!("failed: {}", e.replace('\n', " ")),
                    // A command method's failure, with its last word.
                    (Some(e), Some(tail)) => format!(
                        "failed: {}; stderr ends: {}",
                        e.replace('\n', " "),
                        tail.lines().last().unwrap_or_default()
                    ),
                    (None, _) => "no ground truth".into(),
                }),
            ],
            rule: false,
        })
        .collect();
    let shown = rows.len();
    Some(Table {
        id: "without-figures".into(),
        title: "Rows without figures".into(),
        caption: if shown < total {
            format!("{total} rows have no figures; the first {shown} are listed.")
        } else {
            format!(
                "{total} rows have no figures; they are counted in the cell table, never averaged."
            )
        },
        header: vec![heads(&["Dataset", "View", "Axes", "Method", "Seed", "Why"])],
        rows,
        lead: 6,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::methods::{catalog, reference};
    use sfp_core::metrics::Metrics;

    fn row(dataset: &str, object: &str, method: &str, seed: u64, mae: f64, acc: f64) -> Row {
        let config = if method == "smsfp-no-parg" {
            serde_json::json!({ "method": "smsfp", "parg": false })
        } else {
            serde_json::json!({ "method": method })
        };
        Row {
            key: format!("{dataset}/{object}/{method}/{seed}"),
            dataset: dataset.into(),
            view: format!("{object}_0"),
            object: object.into(),
            axes: Default::default(),
            method: method.into(),
            config,
            seed,
            metrics: Some(Metrics {
                mae_deg: mae,
                rmse_deg: mae + 1.0,
                median_deg: mae - 1.0,
                acc_11_25: acc,
                acc_22_5: acc + 1.0,
                acc_30: acc + 2.0,
                pixels: 100,
                missing: 0,
                specular: None,
            }),
            error: None,
            view_dir: String::new(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    fn bold_texts(t: &Table, r: usize) -> Vec<&str> {
        t.rows[r]
            .cells
            .iter()
            .filter(|c| c.bold)
            .map(|c| c.text.as_str())
            .collect()
    }

    #[test]
    fn a_paired_comparison_of_few_pairs_has_no_interval_and_no_negative_zero() {
        let pair = |n, mean, lo, hi| Paired {
            dataset: "A".into(),
            slice: None,
            reference: "smsfp".into(),
            other: "smith".into(),
            metric: Metric::Mae,
            n,
            mean,
            lo,
            hi,
            wins: 1,
            ties: 0,
            losses: 0,
        };
        let t = paired_table(
            &[pair(1, -3.5, -3.5, -3.5), pair(5, -0.001, -0.004, -0.0001)],
            &[],
        );
        let one = &t.rows[0].cells;
        assert_eq!((one[4].text.as_str(), one[4].bold), ("-3.50", false));
        assert_eq!(one[5].text, "n/a");
        let five = &t.rows[1].cells;
        assert_eq!(five[4].text, "0.00");
        assert_eq!(five[5].text, "[0.00, 0.00]");
        assert!(five[4].bold, "five pairs: the interval counts");
    }

    #[test]
    fn table_one_marks_the_best_of_each_column() {
        // Smith has the lower error in A, SMSfP the higher accuracy; in B
        // SMSfP is better in everything.
        let rows = vec![
            row("A", "cup", "smith", 0, 10.0, 40.0),
            row("A", "cup", "smith", 1, 12.0, 42.0),
            row("A", "cup", "smsfp", 0, 20.0, 60.0),
            row("A", "cup", "smsfp", 1, 22.0, 62.0),
            row("B", "dog", "smith", 0, 30.0, 10.0),
            row("B", "dog", "smsfp", 0, 5.0, 90.0),
            row("B", "dog", "smsfp-no-parg", 0, 7.0, 80.0),
        ];
        let methods = catalog(&rows);
        let stats = Statistics::new(&rows, &methods, reference(&methods));
        let t = paper_table(&stats, &methods);
        // Full methods only; the ablation goes to Table 2.
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[0].cells[0].text, "Smith");
        assert_eq!(t.rows[1].cells[0].text, "SMSfP");
        let texts: Vec<&str> = t.rows[0].cells.iter().map(|c| c.text.as_str()).collect();
        assert_eq!(
            texts,
            [
                "Smith", "11.00", "12.00", "41.0", "42.0", "43.0", "30.00", "31.00", "10.0",
                "11.0", "12.0"
            ]
        );
        assert_eq!(bold_texts(&t, 0), ["11.00", "12.00"]);
        assert_eq!(
            bold_texts(&t, 1),
            [
                "61.0", "62.0", "63.0", "5.00", "6.00", "90.0", "91.0", "92.0"
            ]
        );
        assert!(t.rows[0].cells[1].bold && !t.rows[1].cells[1].bold);
        assert!(t.rows[1].cells[3].bold && !t.rows[0].cells[3].bold);
        assert!(
            t.rows[0].cells[1].title.contains("n = 2"),
            "{:?}",
            t.rows[0].cells[1]
        );
        let md = t.markdown();
        assert!(md.contains("| Dataset A · MAE (°) |"), "{md}");
        assert!(
            md.contains("| Smith | **11.00** | **12.00** | 41.0 |"),
            "{md}"
        );

        let abl = ablation_table(&stats).expect("an ablation");
        // Objects, then the average; groups: the ablation, then SMSfP.
        let names: Vec<&str> = abl.rows.iter().map(|r| r.cells[0].text.as_str()).collect();
        assert_eq!(names, ["cup (A)", "dog (B)", "Average"]);
        assert!(
            abl.header[0][1].text.contains("w/o PARG"),
            "{:?}",
            abl.header
        );
        // dog: SMSfP (columns 6..) beats the ablation (1..) everywhere.
        assert_eq!(
            bold_texts(&abl, 1),
            ["5.00", "6.00", "90.0", "91.0", "92.0"]
        );
        assert!(abl.rows[1].cells[6].bold && !abl.rows[1].cells[1].bold);
        // cup: no ablation rows, so SMSfP alone is best.
        assert_eq!(abl.rows[0].cells[1].text, "—");
        assert!(abl.rows[0].cells[6].bold);
    }

    #[test]
    fn rows_without_figures_are_counted_not_averaged() {
        let mut failed = row("A", "cup", "smith", 2, 0.0, 0.0);
        failed.metrics = None;
        failed.error = Some("boom".into());
        let mut no_gt = row("A", "cup", "smith", 3, 0.0, 0.0);
        no_gt.metrics = None;
        let rows = vec![
            row("A", "cup", "smith", 0, 10.0, 40.0),
            row("A", "cup", "smith", 1, 12.0, 42.0),
            failed,
            no_gt,
        ];
        let methods = catalog(&rows);
        let stats = Statistics::new(&rows, &methods, reference(&methods));
        let t = cell_table(&stats);
        let cells = &stats.cells;
        assert_eq!(cells.len(), 1);
        let f = &cells[0].figures;
        assert_eq!((f.rows, f.failed, f.no_truth), (4, 1, 1));
        let mae = f.get(Metric::Mae).unwrap();
        assert_eq!((mae.n, mae.mean), (2, 11.0));
        assert_eq!(t.rows[0].cells[5].text, "11.00 ± 1.41", "{:?}", t.rows[0]);
        assert_eq!(t.rows[0].cells[5].sub, "[10.00, 12.00]");
        assert!(
            t.markdown().contains("| **11.00 ± 1.41** [10.00, 12.00] |"),
            "{}",
            t.markdown()
        );
        let m = missing_table(&rows, &methods, 10).unwrap();
        assert_eq!(m.rows.len(), 2);
        assert_eq!(m.rows[0].cells[5].text, "failed: boom");
        assert_eq!(m.rows[1].cells[5].text, "no ground truth");
        let csv = cells_csv(cells);
        assert_eq!(csv.lines().count(), 1 + 6);
        assert!(csv.contains("A,—,smith,mae_deg,2,11,"), "{csv}");
    }
}
