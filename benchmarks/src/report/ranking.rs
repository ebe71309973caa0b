//! Who won: on each view the methods ranked by their mean angular error
//! over the view's rows (its noise seeds and swept conditions), and each
//! method's standing over all views — views won, mean rank, mean MAE. A
//! reader of a comparison asks this first, and Table 1's averages do not
//! answer it: one badly failed view can outweigh many won ones. Ablations
//! are left out (Table 2 holds them); a method without figures on a view
//! ranks last there, so failing cannot win.

use super::methods::MethodInfo;
use super::tables::{Cell, Head, Table, TableRow};
use crate::row::Row;
use std::collections::BTreeMap;

/// Views listed in the per-view table, at most.
pub const VIEWS_LISTED: usize = 200;

/// One method's place on one view: its mean MAE, `None` without figures.
#[derive(Clone, Debug, PartialEq)]
pub struct Place {
    pub label: String,
    pub mae: Option<f64>,
}

/// A view's methods, best first.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewRanking {
    pub dataset: String,
    pub view: String,
    pub places: Vec<Place>,
}

/// A method's standing over every ranked view.
#[derive(Clone, Debug, PartialEq)]
pub struct Standing {
    pub label: String,
    /// Views where it ranks first.
    pub won: usize,
    /// Mean of its 1-based rank over the views.
    pub mean_rank: f64,
    /// Mean over the views of its per-view mean MAE (views with figures).
    pub mean_mae: Option<f64>,
}

/// The rankings of every view of `rows` among the full methods of
/// `methods` (views in the rows' order, which the report makes canonical).
pub fn per_view(rows: &[Row], methods: &[MethodInfo]) -> Vec<ViewRanking> {
    let labels: Vec<&str> = methods
        .iter()
        .filter(|m| !m.is_ablation())
        .map(|m| m.label.as_str())
        .collect();
    let mut views: Vec<(String, String)> = Vec::new();
    let mut sums: BTreeMap<(String, String, &str), (f64, usize)> = BTreeMap::new();
    for r in rows.iter().filter(|r| labels.contains(&r.method.as_str())) {
        let view = (r.dataset.clone(), r.view.clone());
        if !views.contains(&view) {
            views.push(view.clone());
        }
        if let Some(m) = &r.metrics {
            let s = sums.entry((view.0, view.1, r.method.as_str())).or_default();
            s.0 += m.mae_deg;
            s.1 += 1;
        }
    }
    // A view without ground truth ranks nobody.
    views.retain(|(d, v)| sums.keys().any(|(sd, sv, _)| sd == d && sv == v));
    views
        .into_iter()
        .map(|(dataset, view)| {
            let mut places: Vec<Place> = labels
                .iter()
                .map(|&label| Place {
                    label: label.to_string(),
                    mae: sums
                        .get(&(dataset.clone(), view.clone(), label))
                        .map(|&(sum, n)| sum / n as f64),
                })
                .collect();
            // Stable: equal errors keep the paper's method order.
            places.sort_by(|a, b| match (a.mae, b.mae) {
                (Some(x), Some(y)) => x.total_cmp(&y),
                (Some(_), None) => std::cmp::Ordering::Less,
                (None, Some(_)) => std::cmp::Ordering::Greater,
                (None, None) => std::cmp::Ordering::Equal,
            });
            ViewRanking {
                dataset,
                view,
                places,
            }
        })
        .collect()
}

/// Each method's standing over `views`, best (lowest mean rank, then
/// lowest mean MAE) first.
pub fn standings(views: &[ViewRanking]) -> Vec<Standing> {
    // Every view places the same methods (`per_view`).
    let Some(first) = views.first() else {
        return Vec::new();
    };
    let mut out: Vec<Standing> = first
        .places
        .iter()
        .map(|p| {
            let (mut won, mut ranks, mut sum, mut with_figures) = (0, 0, 0.0, 0);
            for v in views {
                let rank = v
                    .places
                    .iter()
                    .position(|q| q.label == p.label)
                    .expect("every view places every method");
                ranks += rank + 1;
                if let Some(mae) = v.places[rank].mae {
                    won += usize::from(rank == 0);
                    sum += mae;
                    with_figures += 1;
                }
            }
            Standing {
                label: p.label.clone(),
                won,
                mean_rank: ranks as f64 / views.len() as f64,
                mean_mae: (with_figures > 0).then(|| sum / f64::from(with_figures)),
            }
        })
        .collect();
    out.sort_by(|a, b| {
        a.mean_rank.total_cmp(&b.mean_rank).then(
            a.mean_mae
                .unwrap_or(f64::INFINITY)
                .total_cmp(&b.mean_mae.unwrap_or(f64::INFINITY)),
        )
    });
    out
}

fn display(methods: &[MethodInfo], label: &str) -> String {
    methods
        .iter()
        .find(|m| m.label == label)
        .map_or(label.to_string(), MethodInfo::display)
}

/// One line naming the winner: `SMSfP: first on 9 of 10 views, mean rank
/// 1.1, mean MAE 1.23°`; `None` with fewer than two methods or no view.
pub fn verdict(standings: &[Standing], views: usize, methods: &[MethodInfo]) -> Option<String> {
    let best = standings
        .first()
        .filter(|_| standings.len() > 1 && views > 0)?;
    let mae = best
        .mean_mae
        .map_or(String::new(), |m| format!(", mean MAE {m:.2}°"));
    Some(format!(
        "{}: first on {} of {views} views, mean rank {:.1}{mae}",
        display(methods, &best.label),
        best.won,
        best.mean_rank
    ))
}

fn head(text: &str) -> Head {
    Head {
        text: text.into(),
        span: 1,
    }
}

/// The standings as a table; `None` with fewer than two methods.
pub fn standing_table(
    standings: &[Standing],
    views: usize,
    methods: &[MethodInfo],
) -> Option<Table> {
    if standings.len() < 2 || views == 0 {
        return None;
    }
    let rows = standings
        .iter()
        .enumerate()
        .map(|(k, s)| TableRow {
            cells: vec![
                Cell::text((k + 1).to_string()),
                Cell {
                    bold: k == 0,
                    ..Cell::text(display(methods, &s.label))
                },
                Cell::text(format!("{} / {views}", s.won)),
                Cell::text(format!("{:.2}", s.mean_rank)),
                Cell::text(s.mean_mae.map_or("—".into(), |m| format!("{m:.2}"))),
            ],
            rule: false,
        })
        .collect();
    Some(Table {
        id: "ranking".into(),
        title: "Who won".into(),
        caption: "Methods ranked on every view by their mean MAE over its rows (seeds and \
                  swept conditions), then ordered by mean rank over the views; a method \
                  without figures on a view ranks last there. Mean MAE is the mean over views \
                  of each view's mean."
            .into(),
        header: vec![vec![
            head("Rank"),
            head("Method"),
            head("views won"),
            head("mean rank"),
            head("mean MAE (°)"),
        ]],
        rows,
        lead: 2,
    })
}

/// The per-view rankings as a table (at most [`VIEWS_LISTED`] views);
/// `None` with fewer than two methods.
pub fn view_table(views: &[ViewRanking], methods: &[MethodInfo]) -> Option<Table> {
    if views.is_empty() || views[0].places.len() < 2 {
        return None;
    }
    let rows = views
        .iter()
        .take(VIEWS_LISTED)
        .map(|v| {
            // `<` between figures that differ as shown, `=` between equal ones.
            let mut order = String::new();
            let mut last_shown: Option<String> = None;
            for p in &v.places {
                let shown = p
                    .mae
                    .map_or("no figures".to_string(), |m| format!("{m:.2}"));
                if let Some(last) = &last_shown {
                    order.push_str(if *last == shown { " = " } else { " < " });
                }
                order.push_str(&format!("{} {shown}", display(methods, &p.label)));
                last_shown = Some(shown);
            }
            let winner = v
                .places
                .first()
                .filter(|p| p.mae.is_some())
                .map_or("—".into(), |p| display(methods, &p.label));
            TableRow {
                cells: vec![
                    Cell::text(&v.dataset),
                    Cell::text(&v.view),
                    Cell {
                        bold: true,
                        ..Cell::text(winner)
                    },
                    Cell::text(order),
                ],
                rule: false,
            }
        })
        .collect();
    let more = views.len().saturating_sub(VIEWS_LISTED);
    Some(Table {
        id: "ranking-per-view".into(),
        title: "Ranking per view".into(),
        caption: format!(
            "Each view's methods from best to worst, with their mean MAE (°) over the view's \
             rows (`=` where the figures are equal to two decimals; the order then follows the \
             unrounded ones).{}",
            if more > 0 {
                format!(" The first {VIEWS_LISTED} views are listed, {more} more are not.")
            } else {
                String::new()
            }
        ),
        header: vec![vec![
            head("Dataset"),
            head("View"),
            head("Winner"),
            head("Ranking (MAE °)"),
        ]],
        rows,
        lead: 4,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::methods::catalog;
    use sfp_core::metrics::Metrics;

    fn row(view: &str, method: &str, seed: u64, mae: Option<f64>) -> Row {
        Row {
            key: format!("{view}/{method}/{seed}"),
            dataset: "d".into(),
            view: view.into(),
            object: view.into(),
            axes: Default::default(),
            method: method.into(),
            config: serde_json::json!({ "method": method }),
            seed,
            metrics: mae.map(|m| Metrics {
                mae_deg: m,
                rmse_deg: m,
                median_deg: m,
                acc_11_25: 0.0,
                acc_22_5: 0.0,
                acc_30: 0.0,
                pixels: 1,
                missing: 0,
                specular: None,
            }),
            error: mae.is_none().then(|| "failed".to_string()),
            view_dir: String::new(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    #[test]
    fn views_are_ranked_by_mean_error_and_failing_ranks_last() {
        let rows = vec![
            row("v1", "smith", 0, Some(4.0)),
            row("v1", "smith", 1, Some(2.0)),
            row("v1", "smsfp", 0, Some(1.0)),
            row("v1", "smsfp", 1, Some(4.0)),
            row("v2", "smith", 0, Some(1.0)),
            row("v2", "smsfp", 0, None),
            row("v3", "smith", 0, Some(5.0)),
            row("v3", "smsfp", 0, Some(1.0)),
            row("no_truth", "smith", 0, None),
        ];
        let methods = catalog(&rows);
        let views = per_view(&rows, &methods);
        // v1: Smith 3.0 vs SMSfP 2.5; v2: SMSfP failed; v3: SMSfP ahead;
        // the view without figures is not ranked.
        let winners: Vec<&str> = views.iter().map(|v| v.places[0].label.as_str()).collect();
        assert_eq!(winners, ["smsfp", "smith", "smsfp"]);
        assert_eq!(views[0].places[0].mae, Some(2.5));
        assert_eq!(views[1].places[1].mae, None);
        let s = standings(&views);
        assert_eq!(s[0].label, "smsfp");
        assert_eq!((s[0].won, s[1].won), (2, 1));
        assert!((s[0].mean_rank - 4.0 / 3.0).abs() < 1e-12);
        assert_eq!(s[0].mean_mae, Some((2.5 + 1.0) / 2.0));
        assert_eq!(
            verdict(&s, views.len(), &methods).unwrap(),
            "SMSfP: first on 2 of 3 views, mean rank 1.3, mean MAE 1.75°"
        );
        let table = view_table(&views, &methods).unwrap();
        assert_eq!(table.rows[1].cells[3].text, "Smith 1.00 < SMSfP no figures");
        assert_eq!(table.rows[0].cells[2].text, "SMSfP");
    }

    #[test]
    fn one_method_has_no_ranking() {
        let rows = vec![row("v1", "smith", 0, Some(1.0))];
        let methods = catalog(&rows);
        let views = per_view(&rows, &methods);
        assert!(view_table(&views, &methods).is_none());
        assert!(verdict(&standings(&views), 1, &methods).is_none());
    }
}
