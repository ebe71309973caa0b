//! The report of a sweep folder (`sfp bench`, `sfp bench report DIR`):
//! `DIR/index.html` and `DIR/report.md` with the pictures beside them
//! (`DIR/plots/*.svg`, `DIR/grids/*.png`) and the statistics as numbers
//! (`DIR/stats.csv`).
//!
//! Contents: the paper's Table 1 (per dataset, per method), a per-object
//! table, the paper's Table 2 (SMSfP ablations), paired comparisons of SMSfP
//! with every other label, robustness plots of each metric against each
//! swept axis, picture grids like the paper's Figs. 5–6, every cell with
//! its mean, standard deviation and bootstrap interval ([`stats`] defines
//! the cell and the resampling), the rows without figures, the time per
//! view, the sweep file verbatim and the provenance. Everything but the
//! time table depends only on `results.jsonl` and the pictures, so a
//! re-run gives identical tables.

pub mod axes;
pub mod grids;
pub mod html;
pub mod load;
pub mod methods;
pub mod plots;
pub mod stats;
pub mod tables;

use html::{Context, Fact, PlotGroup, Shown};
use sfp_core::{Error, Result, io};
use std::path::Path;

/// Rows listed in the table of rows without figures, at most.
pub const MISSING_ROWS_LISTED: usize = 200;

/// What [`write`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    /// Rows read from `results.jsonl`.
    pub rows: usize,
    /// Rows with figures.
    pub rows_with_figures: usize,
    /// Cells (dataset, axis values, method).
    pub cells: usize,
    /// Plot files, relative to the folder.
    pub plots: Vec<String>,
    /// Grid pictures, relative to the folder.
    pub grids: Vec<String>,
    /// Pictures the grids could not read.
    pub missing_pictures: Vec<String>,
    /// What the sweep folder lacked (also shown in the report).
    pub notes: Vec<String>,
}

/// Writes the report of the sweep folder `dir` (see the module doc). The
/// `plots/` and `grids/` folders are the report's own and are rewritten.
pub fn write(dir: &Path) -> Result<Written> {
    let files = load::read(dir)?;
    let mut rows = files.rows;
    // A canonical order, so that the report does not depend on the order
    // in which a parallel sweep appended its rows.
    rows.sort_by(|a, b| {
        (&a.dataset, &a.view)
            .cmp(&(&b.dataset, &b.view))
            .then_with(|| axes::cmp_axes(&a.axes, &b.axes))
            .then((&a.method, a.seed, &a.key).cmp(&(&b.method, b.seed, &b.key)))
    });
    let catalog = methods::catalog(&rows);
    let reference = methods::reference(&catalog);

    for sub in ["plots", "grids"] {
        let p = dir.join(sub);
        if p.is_dir() {
            std::fs::remove_dir_all(&p).map_err(|e| Error::io(&p, e))?;
        }
    }

    let mut tables: Vec<Shown> = vec![
        tables::paper_table(&rows, &catalog).into(),
        tables::object_table(&rows, &catalog).into(),
    ];
    if let Some(t) = tables::ablation_table(&rows, &catalog, reference) {
        tables.push(t.into());
    }
    let mut paired = Vec::new();
    if let Some(r) = reference {
        for d in tables::datasets(&rows) {
            for other in catalog.iter().filter(|m| m.label != r.label) {
                paired.extend(stats::paired(&rows, &d, &r.label, &other.label));
            }
        }
    }
    if !paired.is_empty() {
        tables.push(tables::paired_table(&paired, &catalog).into());
    }

    let plots = plots::write(dir, &rows, &catalog)?;
    let mut plot_groups: Vec<PlotGroup> = Vec::new();
    for p in &plots {
        let axis = axes::label(&p.axis);
        match plot_groups.iter_mut().find(|g| g.axis == axis) {
            Some(g) => g.plots.push(p.clone()),
            None => plot_groups.push(PlotGroup {
                axis,
                plots: vec![p.clone()],
            }),
        }
    }
    let grids = grids::write(dir, &rows, &catalog, reference)?;

    let (cell_table, cells) = tables::cell_table(&rows, &catalog);
    io::write_atomic(&dir.join("stats.csv"), tables::cells_csv(&cells).as_bytes())?;
    let mut details: Vec<Shown> = vec![cell_table.into()];
    if let Some(t) = tables::missing_table(&rows, &catalog, MISSING_ROWS_LISTED) {
        details.push(t.into());
    }
    if let Some(t) = &files.timings {
        details.push(tables::timing_table(t, &catalog).into());
    }

    let with_figures = rows.iter().filter(|r| r.metrics.is_some()).count();
    let failed = rows.iter().filter(|r| r.error.is_some()).count();
    let count = |f: &dyn Fn(&crate::sweep::row::Row) -> String| {
        let mut v: Vec<String> = rows.iter().map(f).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    let swept = plots::swept_axes(&rows);
    let mut overview = vec![
        Fact::new(
            "rows",
            format!(
                "{} ({with_figures} with figures, {failed} failed, {} without ground truth)",
                rows.len(),
                rows.len() - with_figures - failed
            ),
        ),
        Fact::new("datasets", tables::datasets(&rows).join(", ")),
        Fact::new(
            "views",
            count(&|r| format!("{}/{}", r.dataset, r.view)).to_string(),
        ),
        Fact::new("noise seeds", count(&|r| r.seed.to_string()).to_string()),
        Fact::new(
            "methods",
            catalog
                .iter()
                .map(|m| {
                    if m.is_ablation() {
                        format!("{} ({})", m.label, m.ablation_text())
                    } else {
                        m.label.clone()
                    }
                })
                .collect::<Vec<_>>()
                .join(", "),
        ),
        Fact::new(
            "swept axes",
            if swept.is_empty() {
                "none".to_string()
            } else {
                swept
                    .iter()
                    .map(|a| axes::label(a))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
        ),
        Fact::new("cells", cells.len().to_string()),
    ];
    overview.push(Fact::new(
        "paired comparisons",
        match reference {
            Some(r) => format!("{} − every other label, on identical inputs", r.label),
            None => "none (no full SMSfP label to compare from)".to_string(),
        },
    ));
    let mut notes = files.notes.clone();
    if grids.dropped_views > 0 {
        notes.push(format!(
            "{} views with pictures are left out of the grids (at most {} per grid).",
            grids.dropped_views,
            grids::MAX_VIEWS
        ));
    }
    if rows.is_empty() {
        notes.push("results.jsonl holds no rows.".into());
    }

    let mut provenance = Vec::new();
    let mut crates = Vec::new();
    match &files.provenance {
        Some(p) => {
            let or_unknown = |v: &Option<String>| v.clone().unwrap_or_else(|| "unknown".into());
            provenance.push(Fact::new("version", or_unknown(&p.version)));
            provenance.push(Fact::new("commit", or_unknown(&p.commit)));
            provenance.push(Fact::new("CPU", or_unknown(&p.cpu)));
            provenance.push(Fact::new("threads", or_unknown(&p.threads)));
            provenance.push(Fact::new("started", or_unknown(&p.started)));
            crates = p
                .crates
                .iter()
                .map(|(k, v)| Fact::new(k.clone(), v.clone()))
                .collect();
        }
        None => provenance.push(Fact::new("provenance", "unknown (no provenance.json)")),
    }

    let context = Context {
        title: "Shape-from-polarization benchmark".into(),
        columns: vec![
            Fact::new(
                "MAE, RMSE, median",
                "mean, root-mean-square and median angle between the estimated and the true \
                 normal over the object mask, in degrees (two decimals; lower is better)",
            ),
            Fact::new(
                "<11.25°, <22.5°, <30°",
                "share of mask pixels whose angular error is below the threshold, in percent \
                 (one decimal; higher is better)",
            ),
            Fact::new(
                "bold",
                "the best value of its column among rows that compare methods on the same inputs",
            ),
            Fact::new(
                "interval",
                format!(
                    "95% percentile bootstrap of the mean over rows ({} resamples, seeded: \
                     identical on re-run)",
                    stats::RESAMPLES
                ),
            ),
        ],
        conventions: vec![
            "Normals are unit vectors in the camera frame (x right, y up, z towards the camera); \
             normal maps show (n + 1)/2 as RGB."
                .into(),
            "Mask pixels where a method returns no normal count as 90° errors, so a method \
             cannot win by abstaining."
                .into(),
        ],
        overview,
        tables,
        plot_caption: "Each point is the mean over every row with that axis value (all datasets, \
                       views, seeds and values of the other axes); the band and whiskers are \
                       its 95% bootstrap interval."
            .into(),
        plot_groups,
        grids: grids.grids.clone(),
        missing_pictures: grids.missing.clone(),
        details,
        sweep_toml: files.sweep_toml.clone(),
        provenance,
        crates,
        notes: notes.clone(),
    };
    io::write_atomic(&dir.join("index.html"), html::html(&context)?.as_bytes())?;
    io::write_atomic(&dir.join("report.md"), html::markdown(&context)?.as_bytes())?;

    Ok(Written {
        rows: rows.len(),
        rows_with_figures: with_figures,
        cells: cells.len(),
        plots: plots.into_iter().map(|p| p.file).collect(),
        grids: grids.grids.into_iter().map(|g| g.file).collect(),
        missing_pictures: grids.missing,
        notes,
    })
}
