//! Statistics of a sweep: per-cell means, standard deviations and bootstrap
//! confidence intervals, and paired comparisons of two methods on identical
//! inputs.
//!
//! - **Cell**: the rows of one (dataset, all axis values, method label).
//!   Its rows differ by view and noise seed only.
//! - **Unit of resampling**: one row, i.e. one (view, seed) reconstruction
//!   and its figures (a row's figures are already means over its pixels).
//!   Rows without figures (no ground truth, failed) are counted, never
//!   averaged.
//! - **Interval**: percentile bootstrap of the mean, [`RESAMPLES`] resamples
//!   with replacement, 2.5th and 97.5th percentiles (linear interpolation
//!   between order statistics). The generator (PCG64) is seeded from a hash
//!   of the cell's identity and the metric, so a report is identical on
//!   re-run and adding a cell does not move the others' intervals.
//! - **Paired comparison** `reference − other`: rows of two method labels
//!   matched by (dataset, view, axis values, seed); mean difference, its
//!   bootstrap interval over the pairs, and wins/ties/losses of the
//!   reference (a win is a lower error or a higher accuracy; a tie is a
//!   difference of at most [`TIE`]).
//! - **Once per report**: [`Statistics`] holds every figure a report shows
//!   (each table's [`Pool`]s of rows, every cell, every plot point, the
//!   paired comparisons); tables, plots and pages read it and never
//!   resample. A pool is seeded by its own identity, so the same rows
//!   pooled by two tables get two independent, stable intervals.

use super::axes;
use super::methods::MethodInfo;
use crate::row::{AxisValue, Row};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::Serialize;
use sfp_core::metrics::Metrics;
use std::collections::{BTreeMap, HashMap};

/// Bootstrap resamples per interval.
pub const RESAMPLES: usize = 2000;

/// Coverage of the intervals.
pub const CONFIDENCE: f64 = 0.95;

/// Largest difference counted as a tie in paired comparisons.
pub const TIE: f64 = 1e-9;

/// One figure of `Metrics`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Metric {
    Mae,
    Rmse,
    Median,
    Acc11,
    Acc22,
    Acc30,
}

impl Metric {
    pub const ALL: [Metric; 6] = [
        Metric::Mae,
        Metric::Rmse,
        Metric::Median,
        Metric::Acc11,
        Metric::Acc22,
        Metric::Acc30,
    ];

    /// The five figures of the paper's Tables 1 and 2.
    pub const PAPER: [Metric; 5] = [
        Metric::Mae,
        Metric::Rmse,
        Metric::Acc11,
        Metric::Acc22,
        Metric::Acc30,
    ];

    /// Field name in `metrics.json` (also used in file names).
    pub fn key(self) -> &'static str {
        match self {
            Metric::Mae => "mae_deg",
            Metric::Rmse => "rmse_deg",
            Metric::Median => "median_deg",
            Metric::Acc11 => "acc_11_25",
            Metric::Acc22 => "acc_22_5",
            Metric::Acc30 => "acc_30",
        }
    }

    /// Column name.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mae => "MAE",
            Metric::Rmse => "RMSE",
            Metric::Median => "median",
            Metric::Acc11 => "<11.25°",
            Metric::Acc22 => "<22.5°",
            Metric::Acc30 => "<30°",
        }
    }

    /// Axis label with unit.
    pub fn label(self) -> String {
        match self {
            Metric::Mae => "mean angular error (°)".into(),
            Metric::Rmse => "RMS angular error (°)".into(),
            Metric::Median => "median angular error (°)".into(),
            _ => format!("pixels with error {} (%)", self.name()),
        }
    }

    /// `°` for errors, `%` for accuracies.
    pub fn unit(self) -> &'static str {
        if self.is_error() { "°" } else { "%" }
    }

    /// Errors (lower is better) as opposed to accuracies.
    pub fn is_error(self) -> bool {
        matches!(self, Metric::Mae | Metric::Rmse | Metric::Median)
    }

    pub fn of(self, m: &Metrics) -> f64 {
        match self {
            Metric::Mae => m.mae_deg,
            Metric::Rmse => m.rmse_deg,
            Metric::Median => m.median_deg,
            Metric::Acc11 => m.acc_11_25,
            Metric::Acc22 => m.acc_22_5,
            Metric::Acc30 => m.acc_30,
        }
    }

    /// Angles with two decimals, accuracies with one.
    pub fn format(self, v: f64) -> String {
        if !v.is_finite() {
            "—".into()
        } else {
            fixed(v, self.decimals(), false)
        }
    }

    /// Decimals a figure of this metric is printed with.
    pub fn decimals(self) -> usize {
        if self.is_error() { 2 } else { 1 }
    }

    /// True when `a` is better than `b`.
    pub fn better(self, a: f64, b: f64) -> bool {
        if self.is_error() { a < b } else { a > b }
    }
}

/// `v` with `decimals` decimals (a `+` before positive values when
/// `signed`), and never a "−0.00": a value that rounds to zero has no sign.
pub fn fixed(v: f64, decimals: usize, signed: bool) -> String {
    let text = if signed {
        format!("{v:+.decimals$}")
    } else {
        format!("{v:.decimals$}")
    };
    let digits = text.trim_start_matches(['+', '-']);
    if digits.chars().all(|c| c == '0' || c == '.') {
        digits.to_string()
    } else {
        text
    }
}

/// Mean, spread and bootstrap interval of a sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation (`n − 1`); `None` for one value.
    pub sd: Option<f64>,
    /// Bootstrap interval of the mean.
    pub lo: f64,
    pub hi: f64,
}

/// FNV-1a hash of `parts` (with separators): the seed of an interval.
pub fn seed_of(parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for b in part.bytes().chain([0xff]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// The `q` quantile of sorted `values` (linear interpolation between order
/// statistics); NaN for no values.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let pos = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let i = (pos.floor() as usize).min(n - 2);
            let f = pos - i as f64;
            sorted[i] * (1.0 - f) + sorted[i + 1] * f
        }
    }
}

/// Percentile bootstrap interval of the mean of `values` ([`RESAMPLES`]
/// resamples, seeded by `seed`); NaNs for no values.
pub fn bootstrap_mean_ci(values: &[f64], seed: u64) -> (f64, f64) {
    let n = values.len();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    if n == 1 {
        return (values[0], values[0]);
    }
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut means: Vec<f64> = (0..RESAMPLES)
        .map(|_| (0..n).map(|_| values[rng.random_range(0..n)]).sum::<f64>() / n as f64)
        .collect();
    means.sort_by(f64::total_cmp);
    let tail = (1.0 - CONFIDENCE) / 2.0;
    (quantile(&means, tail), quantile(&means, 1.0 - tail))
}

/// The mean of `values` (NaN for none).
pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// [`Summary`] of `values`, or `None` when there are none.
pub fn summarize(values: &[f64], seed: u64) -> Option<Summary> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    let mean = mean(values);
    let sd = (n > 1)
        .then(|| (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt());
    let (lo, hi) = bootstrap_mean_ci(values, seed);
    Some(Summary {
        n,
        mean,
        sd,
        lo,
        hi,
    })
}

/// The figures of one pool of rows: how many rows it holds, how many of
/// them failed or have no ground truth, and the [`Summary`] of every metric
/// over those with figures.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Figures {
    pub rows: usize,
    pub failed: usize,
    pub no_truth: usize,
    pub stats: Vec<(Metric, Summary)>,
}

impl Figures {
    /// The figures of `rows`, seeded by `id` (the identity of the pool) and
    /// the metric.
    pub fn of(rows: &[&Row], id: &str) -> Figures {
        let figures: Vec<&Metrics> = rows.iter().filter_map(|r| r.metrics.as_ref()).collect();
        let stats = Metric::ALL
            .iter()
            .filter_map(|&metric| {
                let values: Vec<f64> = figures.iter().map(|m| metric.of(m)).collect();
                summarize(&values, seed_of(&[id, metric.key()])).map(|s| (metric, s))
            })
            .collect();
        Figures {
            rows: rows.len(),
            failed: rows.iter().filter(|r| r.error.is_some()).count(),
            no_truth: rows
                .iter()
                .filter(|r| r.error.is_none() && r.metrics.is_none())
                .count(),
            stats,
        }
    }

    /// The summary of `metric`; `None` when no row has figures.
    pub fn get(&self, metric: Metric) -> Option<&Summary> {
        self.stats
            .iter()
            .find(|(m, _)| *m == metric)
            .map(|(_, s)| s)
    }

    /// Rows with figures.
    pub fn with_figures(&self) -> usize {
        self.stats.first().map_or(0, |(_, s)| s.n)
    }
}

/// `reference − other` over matched rows, for one metric.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Paired {
    pub dataset: String,
    /// The axis value every pair shares (`noise_full_well=1250`); `None`:
    /// every input of the dataset.
    pub slice: Option<String>,
    pub reference: String,
    pub other: String,
    pub metric: Metric,
    /// Matched pairs.
    pub n: usize,
    pub mean: f64,
    pub lo: f64,
    pub hi: f64,
    /// Pairs where the reference is better, equal, worse.
    pub wins: usize,
    pub ties: usize,
    pub losses: usize,
}

/// Fewest pairs a paired comparison's interval is shown for: a bootstrap of
/// fewer is no interval (one pair gave "[−3.50, −3.50]", in bold).
pub const MIN_PAIRS: usize = 5;

impl Paired {
    /// Whether there are pairs enough for the interval to mean something.
    pub fn has_interval(&self) -> bool {
        self.n >= MIN_PAIRS
    }

    /// Share of pairs the reference wins, percent.
    pub fn win_rate(&self) -> f64 {
        100.0 * self.wins as f64 / self.n.max(1) as f64
    }
}

/// Identity of a row's input: (view, axis values, seed) within a dataset.
fn input_key(r: &Row) -> (String, String, u64) {
    let axes = serde_json::to_string(&r.axes).expect("axes serialise");
    (r.view.clone(), axes, r.seed)
}

/// Paired comparisons `reference − other` in `dataset`, one per metric,
/// over the inputs both labels have figures for (first row of a duplicated
/// input). Empty when there is no such input.
pub fn paired(rows: &[Row], dataset: &str, reference: &str, other: &str) -> Vec<Paired> {
    paired_in(rows, dataset, None, reference, other, &Metric::ALL)
}

/// As [`paired`], for `metrics` only and, with a `slice` `(axis, value)`,
/// over the inputs whose `axis` has that value: a sweep's claim is often
/// about one exposure or index, which pooling over the axis would hide.
fn paired_in(
    rows: &[Row],
    dataset: &str,
    slice: Option<(&str, &AxisValue)>,
    reference: &str,
    other: &str,
    metrics: &[Metric],
) -> Vec<Paired> {
    use std::collections::BTreeMap;
    let in_slice = |r: &Row| slice.is_none_or(|(axis, value)| r.axes.get(axis) == Some(value));
    let slice_text = slice.map(|(axis, value)| format!("{axis}={value}"));
    let figures = |label: &str| {
        let mut by_input: BTreeMap<(String, String, u64), &Metrics> = BTreeMap::new();
        for r in rows
            .iter()
            .filter(|r| r.dataset == dataset && r.method == label && in_slice(r))
        {
            if let Some(m) = &r.metrics {
                by_input.entry(input_key(r)).or_insert(m);
            }
        }
        by_input
    };
    let (a, b) = (figures(reference), figures(other));
    let pairs: Vec<(&Metrics, &Metrics)> = a
        .iter()
        .filter_map(|(k, ma)| b.get(k).map(|mb| (*ma, *mb)))
        .collect();
    if pairs.is_empty() {
        return Vec::new();
    }
    metrics
        .iter()
        .map(|&metric| {
            let diffs: Vec<f64> = pairs
                .iter()
                .map(|(x, y)| metric.of(x) - metric.of(y))
                .collect();
            let (mut wins, mut ties, mut losses) = (0, 0, 0);
            for &d in &diffs {
                if d.abs() <= TIE {
                    ties += 1;
                } else if metric.better(d, 0.0) {
                    wins += 1;
                } else {
                    losses += 1;
                }
            }
            // Unsliced comparisons keep the seed they always had.
            let seed = match &slice_text {
                None => seed_of(&["paired", dataset, reference, other, metric.key()]),
                Some(t) => seed_of(&["paired", dataset, t, reference, other, metric.key()]),
            };
            let s = summarize(&diffs, seed).expect("pairs are not empty");
            Paired {
                dataset: dataset.to_string(),
                slice: slice_text.clone(),
                reference: reference.to_string(),
                other: other.to_string(),
                metric,
                n: diffs.len(),
                mean: s.mean,
                lo: s.lo,
                hi: s.hi,
                wins,
                ties,
                losses,
            }
        })
        .collect()
}

/// A pool of rows that a table of the report summarises. Each pool is
/// seeded by its own identity (`Pool::id`), so the same rows in two tables
/// get two independent, stable intervals.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Pool {
    /// Every row of a label in a dataset (Table 1).
    Dataset { dataset: String, method: String },
    /// Every row of a label on one object of a dataset (per-object table).
    Object {
        dataset: String,
        object: String,
        method: String,
    },
    /// The same rows as [`Pool::Object`], for Table 2.
    AblationObject {
        dataset: String,
        object: String,
        method: String,
    },
    /// Every row of a label (Table 2's average).
    AblationAverage { method: String },
}

impl Pool {
    /// The identity the pool's intervals are seeded by.
    fn id(&self) -> String {
        match self {
            Pool::Dataset { dataset, method } => format!("table1/{dataset}/{method}"),
            Pool::Object {
                dataset,
                object,
                method,
            } => format!("object/{dataset}/{object}/{method}"),
            Pool::AblationObject {
                dataset,
                object,
                method,
            } => format!("ablation/{dataset}/{object}/{method}"),
            Pool::AblationAverage { method } => format!("ablation/average/{method}"),
        }
    }

    fn holds(&self, r: &Row) -> bool {
        match self {
            Pool::Dataset { dataset, method } => &r.dataset == dataset && &r.method == method,
            Pool::Object {
                dataset,
                object,
                method,
            }
            | Pool::AblationObject {
                dataset,
                object,
                method,
            } => &r.dataset == dataset && &r.object == object && &r.method == method,
            Pool::AblationAverage { method } => &r.method == method,
        }
    }
}

/// The statistics of one cell (dataset, axis values, method label).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CellStats {
    pub dataset: String,
    pub axes: BTreeMap<String, AxisValue>,
    pub method: String,
    pub display: String,
    pub figures: Figures,
}

/// The points of the robustness plots of one swept axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisPoints {
    pub axis: String,
    /// The axis's values among rows with figures, in order.
    pub values: Vec<AxisValue>,
    /// Per method label (report order), per value: every row of the label
    /// with that value, over all datasets, views, seeds and other axes.
    pub figures: Vec<Vec<Figures>>,
}

/// The labels and objects of Table 2.
#[derive(Clone, Debug, PartialEq)]
pub struct Ablation {
    /// Every SMSfP ablation, then the full reference.
    pub groups: Vec<MethodInfo>,
    /// The (dataset, object) pairs they have rows of, sorted.
    pub objects: Vec<(String, String)>,
}

/// Every statistic a report shows, computed once from its rows: the
/// tables, plots and pages read them and never resample.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Statistics {
    /// Datasets of the rows, sorted.
    pub datasets: Vec<String>,
    /// (dataset, object) of the rows, sorted.
    pub objects: Vec<(String, String)>,
    /// Axis names of the rows, sorted.
    pub axis_names: Vec<String>,
    /// What Table 2 lists; `None` without an ablation or a reference.
    pub ablation: Option<Ablation>,
    pools: HashMap<Pool, Figures>,
    /// Every cell, ordered by dataset, axis values, then method label.
    pub cells: Vec<CellStats>,
    /// Every swept axis (two or more values among rows with figures).
    pub axes: Vec<AxisPoints>,
    /// `reference − other` for every other label, per dataset and metric.
    pub paired: Vec<Paired>,
    /// The same for the MAE only, per dataset and value of every swept axis.
    pub paired_by_axis: Vec<Paired>,
}

impl Statistics {
    /// The statistics of `rows` (in the report's order) for the labels of
    /// `methods`, paired comparisons from `reference`.
    pub fn new(rows: &[Row], methods: &[MethodInfo], reference: Option<&MethodInfo>) -> Statistics {
        let datasets = sorted_unique(rows.iter().map(|r| r.dataset.clone()));
        let objects = sorted_unique(rows.iter().map(|r| (r.dataset.clone(), r.object.clone())));
        let mut pools = Vec::new();
        for d in &datasets {
            for m in methods.iter().filter(|m| !m.is_ablation()) {
                pools.push(Pool::Dataset {
                    dataset: d.clone(),
                    method: m.label.clone(),
                });
            }
        }
        for (d, o) in &objects {
            for m in methods {
                pools.push(Pool::Object {
                    dataset: d.clone(),
                    object: o.clone(),
                    method: m.label.clone(),
                });
            }
        }
        let ablation = ablation_groups(methods, reference).map(|groups| {
            let objects = sorted_unique(
                rows.iter()
                    .filter(|r| groups.iter().any(|g| g.label == r.method))
                    .map(|r| (r.dataset.clone(), r.object.clone())),
            );
            for g in &groups {
                for (d, o) in &objects {
                    pools.push(Pool::AblationObject {
                        dataset: d.clone(),
                        object: o.clone(),
                        method: g.label.clone(),
                    });
                }
                pools.push(Pool::AblationAverage {
                    method: g.label.clone(),
                });
            }
            Ablation { groups, objects }
        });
        let pools = pools
            .into_iter()
            .filter_map(|pool| {
                let selected: Vec<&Row> = rows.iter().filter(|r| pool.holds(r)).collect();
                let figures = Figures::of(&selected, &pool.id());
                (!selected.is_empty()).then_some((pool, figures))
            })
            .collect();
        let axes = axis_points(rows, methods);
        let (mut paired, mut paired_by_axis) = (Vec::new(), Vec::new());
        if let Some(r) = reference {
            for d in &datasets {
                for other in methods.iter().filter(|m| m.label != r.label) {
                    paired.extend(self::paired(rows, d, &r.label, &other.label));
                }
                for a in &axes {
                    for value in &a.values {
                        for other in methods.iter().filter(|m| m.label != r.label) {
                            paired_by_axis.extend(paired_in(
                                rows,
                                d,
                                Some((&a.axis, value)),
                                &r.label,
                                &other.label,
                                &[Metric::Mae],
                            ));
                        }
                    }
                }
            }
        }
        Statistics {
            axis_names: sorted_unique(rows.iter().flat_map(|r| r.axes.keys().cloned())),
            cells: cells(rows, methods),
            axes,
            datasets,
            objects,
            ablation,
            pools,
            paired,
            paired_by_axis,
        }
    }

    /// The figures of `pool`; `None` when it holds no row.
    pub fn get(&self, pool: &Pool) -> Option<&Figures> {
        self.pools.get(pool)
    }
}

fn sorted_unique<T: Ord>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut v: Vec<T> = items.collect();
    v.sort();
    v.dedup();
    v
}

/// The labels of Table 2: every SMSfP ablation, then the full `reference`;
/// `None` without either.
fn ablation_groups(
    methods: &[MethodInfo],
    reference: Option<&MethodInfo>,
) -> Option<Vec<MethodInfo>> {
    let reference = reference?;
    let mut groups: Vec<MethodInfo> = methods
        .iter()
        .filter(|m| m.is_ablation())
        .cloned()
        .collect();
    if groups.is_empty() {
        return None;
    }
    groups.push(reference.clone());
    Some(groups)
}

/// The cells of `rows`, ordered by dataset, axis values, then method as in
/// `methods`.
fn cells(rows: &[Row], methods: &[MethodInfo]) -> Vec<CellStats> {
    let mut keys: Vec<(&str, &BTreeMap<String, AxisValue>, usize)> = rows
        .iter()
        .map(|r| {
            let m = methods
                .iter()
                .position(|m| m.label == r.method)
                .unwrap_or(usize::MAX);
            (r.dataset.as_str(), &r.axes, m)
        })
        .collect();
    keys.sort_by(|a, b| {
        a.0.cmp(b.0)
            .then_with(|| axes::cmp_axes(a.1, b.1))
            .then(a.2.cmp(&b.2))
    });
    keys.dedup();
    keys.into_iter()
        .map(|(d, ax, m)| {
            let info = &methods[m];
            let selected: Vec<&Row> = rows
                .iter()
                .filter(|r| r.dataset == d && &r.axes == ax && r.method == info.label)
                .collect();
            let id = format!(
                "cell/{d}/{}/{}",
                serde_json::to_string(ax).expect("axes serialise"),
                info.label
            );
            CellStats {
                dataset: d.to_string(),
                axes: ax.clone(),
                method: info.label.clone(),
                display: info.display(),
                figures: Figures::of(&selected, &id),
            }
        })
        .collect()
}

/// Distinct values of `axis` among rows with figures, in order.
fn values_of(rows: &[Row], axis: &str) -> Vec<AxisValue> {
    let mut v: Vec<AxisValue> = rows
        .iter()
        .filter(|r| r.metrics.is_some())
        .filter_map(|r| r.axes.get(axis).cloned())
        .collect();
    v.sort_by(axes::cmp_value);
    v.dedup();
    v
}

/// The plot points of every axis with two or more values among rows with
/// figures, axes sorted.
fn axis_points(rows: &[Row], methods: &[MethodInfo]) -> Vec<AxisPoints> {
    let names = sorted_unique(rows.iter().flat_map(|r| r.axes.keys().cloned()));
    names
        .into_iter()
        .filter_map(|axis| {
            let values = values_of(rows, &axis);
            if values.len() < 2 {
                return None;
            }
            let figures = methods
                .iter()
                .map(|m| {
                    values
                        .iter()
                        .map(|value| {
                            let selected: Vec<&Row> = rows
                                .iter()
                                .filter(|r| r.method == m.label && r.axes.get(&axis) == Some(value))
                                .collect();
                            let id = format!("plot/{axis}/{value}/{}", m.label);
                            Figures::of(&selected, &id)
                        })
                        .collect()
                })
                .collect();
            Some(AxisPoints {
                axis,
                values,
                figures,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bootstrap_interval_holds_the_mean_and_has_the_normal_width() {
        // 0, 1, …, 99: mean 49.5, sd 29.01, standard error 2.90; a 95%
        // interval is about ±1.96 · 2.90 = ±5.7 wide.
        let values: Vec<f64> = (0..100).map(f64::from).collect();
        let s = summarize(&values, 7).unwrap();
        assert!((s.mean - 49.5).abs() < 1e-12);
        assert!((s.sd.unwrap() - 29.011).abs() < 1e-3, "{s:?}");
        assert!(s.lo < s.mean && s.mean < s.hi, "{s:?}");
        let half = (s.hi - s.lo) / 2.0;
        assert!((4.8..6.6).contains(&half), "half width {half}");
        // Seeded: the same interval again, another with another seed.
        assert_eq!(summarize(&values, 7).unwrap(), s);
        assert_ne!(summarize(&values, 8).unwrap().lo, s.lo);
        // Four times the rows: half the width.
        let more: Vec<f64> = (0..400).map(|i| f64::from(i % 100)).collect();
        let m = summarize(&more, 7).unwrap();
        let ratio = (m.hi - m.lo) / (s.hi - s.lo);
        assert!((0.4..0.6).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn degenerate_samples() {
        assert_eq!(summarize(&[], 1), None);
        let one = summarize(&[3.0], 1).unwrap();
        assert_eq!((one.mean, one.sd, one.lo, one.hi), (3.0, None, 3.0, 3.0));
        let same = summarize(&[2.0; 5], 1).unwrap();
        assert_eq!((same.lo, same.hi, same.sd), (2.0, 2.0, Some(0.0)));
        assert_eq!(quantile(&[0.0, 10.0], 0.25), 2.5);
    }

    fn row(method: &str, view: &str, seed: u64, mae: f64, acc: f64) -> Row {
        Row {
            key: format!("{method}-{view}-{seed}"),
            dataset: "d".into(),
            view: view.into(),
            object: "o".into(),
            axes: [("eta".to_string(), AxisValue::Number(1.5))].into(),
            method: method.into(),
            config: serde_json::json!({ "method": method }),
            seed,
            metrics: Some(Metrics {
                mae_deg: mae,
                rmse_deg: mae,
                median_deg: mae,
                acc_11_25: acc,
                acc_22_5: acc,
                acc_30: acc,
                pixels: 10,
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

    #[test]
    fn paired_differences_and_win_counts() {
        let mut rows = Vec::new();
        for (i, (a, b)) in [(10.0, 12.0), (10.0, 15.0), (20.0, 18.0), (5.0, 5.0)]
            .into_iter()
            .enumerate()
        {
            rows.push(row("a", "v", i as u64, a, 100.0 - a));
            rows.push(row("b", "v", i as u64, b, 100.0 - b));
        }
        // An unmatched row is left out.
        rows.push(row("b", "w", 0, 90.0, 0.0));
        let p = paired(&rows, "d", "a", "b");
        let mae = p.iter().find(|p| p.metric == Metric::Mae).unwrap();
        assert_eq!(mae.n, 4);
        assert!((mae.mean - (-2.0 - 5.0 + 2.0 + 0.0) / 4.0).abs() < 1e-12);
        assert_eq!((mae.wins, mae.ties, mae.losses), (2, 1, 1));
        assert!(mae.lo <= mae.mean && mae.mean <= mae.hi);
        // Accuracy: higher is better, so the same rows win.
        let acc = p.iter().find(|p| p.metric == Metric::Acc11).unwrap();
        assert_eq!((acc.wins, acc.ties, acc.losses), (2, 1, 1));
        assert!((acc.mean - 1.25).abs() < 1e-12);
        // A method against itself: zero difference, every pair a tie.
        for q in paired(&rows, "d", "a", "a") {
            assert_eq!((q.mean, q.lo, q.hi), (0.0, 0.0, 0.0));
            assert_eq!((q.wins, q.ties, q.losses), (0, 4, 0));
        }
        assert!(paired(&rows, "d", "a", "nope").is_empty());
    }

    #[test]
    fn paired_per_axis_value_keeps_what_pooling_hides() {
        // "a" wins by 4 at full well 20000 and loses by 2 at 1250: pooled,
        // +1 per pair; per value, −4 and +2.
        let mut rows = Vec::new();
        for (seed, well, a, b) in [(0, 20000.0, 10.0, 14.0), (0, 1250.0, 22.0, 20.0)] {
            for (label, mae) in [("a", a), ("b", b)] {
                let mut r = row(label, "v", seed, mae, 0.0);
                r.axes
                    .insert("noise_full_well".into(), AxisValue::Number(well));
                rows.push(r);
            }
        }
        let pooled = paired(&rows, "d", "a", "b");
        assert!((pooled[0].mean + 1.0).abs() < 1e-12 && pooled[0].slice.is_none());
        let info = |label: &str| MethodInfo {
            label: label.into(),
            method: label.into(),
            ablated: Vec::new(),
        };
        let methods = [info("a"), info("b")];
        let stats = Statistics::new(&rows, &methods, Some(&methods[0]));
        let by: Vec<(String, f64)> = stats
            .paired_by_axis
            .iter()
            .map(|p| (p.slice.clone().unwrap(), p.mean))
            .collect();
        assert_eq!(
            by,
            [
                ("noise_full_well=1250".to_string(), 2.0),
                ("noise_full_well=20000".to_string(), -4.0)
            ]
        );
        assert!(stats.paired_by_axis.iter().all(|p| p.metric == Metric::Mae));
    }
}
