//! The report of a sweep folder (`sfp bench`, `sfp bench report DIR`):
//! `DIR/index.html` and `DIR/report.md` with the pictures beside them
//! (`DIR/plots/*.svg`, `DIR/grids/*.png`) and the statistics as numbers
//! (`DIR/stats.csv`).
//!
//! Contents: the paper's Table 1 (per dataset, per method), a per-object
//! table, the paper's Table 2 (SMSfP ablations), paired comparisons of SMSfP
//! with every other label, the specular labelling against the mixture's
//! ground truth ([`labelling`]), the estimated refractive index and light
//! against each swept axis ([`estimates`]), robustness plots of each metric against each
//! swept axis, picture grids like the paper's Figs. 5–6, every cell with
//! its mean, standard deviation and bootstrap interval ([`stats`] defines
//! the cell and the resampling), the rows without figures, the time per
//! view, the sweep file verbatim and the provenance. Everything but the
//! time table depends only on `results.jsonl` and the pictures, so a
//! re-run gives identical tables.

pub mod axes;
pub mod estimates;
pub mod grids;
pub mod html;
pub mod labelling;
pub mod load;
pub mod methods;
pub mod plots;
pub mod ranking;
pub mod stats;
pub mod summary;
pub mod tables;

use crate::row::Row;
use html::{Context, Fact, PlotGroup, Shown};
use load::Provenance;
use methods::MethodInfo;
use plots::Plot;
use sfp_core::{Error, Result, io};
use stats::Statistics;
use std::path::Path;

/// The contact sheet `sfp demo` leaves beside its report.
pub const SHEET: &str = "sheet.png";

/// Rows listed in the table of rows without figures, at most.
pub const MISSING_ROWS_LISTED: usize = 200;

/// What [`write()`] wrote.
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

    let stats = Statistics::new(&rows, &catalog, reference);
    let views = ranking::per_view(&rows, &catalog);
    let standings = ranking::standings(&views);
    let mut tables: Vec<Shown> = Vec::new();
    if let Some(t) = ranking::standing_table(&standings, views.len(), &catalog) {
        tables.push(t.into());
    }
    if let Some(t) = ranking::view_table(&views, &catalog) {
        tables.push(t.into());
    }
    tables.push(tables::paper_table(&stats, &catalog).into());
    tables.push(tables::object_table(&stats, &catalog).into());
    if let Some(t) = tables::ablation_table(&stats) {
        tables.push(t.into());
    }
    // A comparison of fewer pairs than an interval needs is no evidence
    // (two pairs read "100% win rate"): the ranking above covers those.
    let paired = with_interval(&stats.paired);
    if !paired.is_empty() {
        tables.push(tables::paired_table(&paired, &catalog).into());
    }
    let paired_by_axis = with_interval(&stats.paired_by_axis);
    if !paired_by_axis.is_empty() {
        tables.push(tables::paired_by_axis_table(&paired_by_axis, &catalog).into());
    }
    if let Some(t) = labelling::table(&rows, &catalog) {
        tables.push(t.into());
    }
    if let Some(t) = estimates::table(&rows, &stats, &catalog) {
        tables.push(t.into());
    }

    let plots = plots::write(dir, &stats, &catalog)?;
    let grids = grids::write(dir, &rows, &catalog, reference)?;

    io::write_atomic(
        &dir.join("stats.csv"),
        tables::cells_csv(&stats.cells).as_bytes(),
    )?;
    let mut details: Vec<Shown> = vec![tables::cell_table(&stats).into()];
    if let Some(t) = tables::missing_table(&rows, &catalog, MISSING_ROWS_LISTED) {
        details.push(t.into());
    }
    if let Some(t) = &files.timings {
        details.push(tables::timing_table(t, &catalog).into());
    }

    let with_figures = rows.iter().filter(|r| r.metrics.is_some()).count();
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

    let (provenance, crates) = provenance_facts(files.provenance.as_ref());

    let context = Context {
        resamples: stats::RESAMPLES,
        overview: overview(&rows, &stats, &catalog, reference, &standings, views.len()),
        swept: !stats.axes.is_empty(),
        tables,
        plot_groups: plot_groups(&plots),
        grids: grids.grids.clone(),
        sheet: dir.join(SHEET).is_file().then(|| SHEET.to_string()),
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
        cells: stats.cells.len(),
        plots: plots.into_iter().map(|p| p.file).collect(),
        grids: grids.grids.into_iter().map(|g| g.file).collect(),
        missing_pictures: grids.missing,
        notes,
    })
}

/// The paired comparisons with pairs enough for an interval.
fn with_interval(paired: &[stats::Paired]) -> Vec<stats::Paired> {
    paired
        .iter()
        .filter(|p| p.has_interval())
        .cloned()
        .collect()
}

/// The plots grouped by swept axis, in order.
fn plot_groups(plots: &[Plot]) -> Vec<PlotGroup> {
    let mut groups: Vec<PlotGroup> = Vec::new();
    for p in plots {
        let axis = axes::label(&p.axis);
        match groups.iter_mut().find(|g| g.axis == axis) {
            Some(g) => g.plots.push(p.clone()),
            None => groups.push(PlotGroup {
                axis,
                plots: vec![p.clone()],
            }),
        }
    }
    groups
}

/// The overview list: what the rows hold and how the report compares them.
fn overview(
    rows: &[Row],
    stats: &Statistics,
    catalog: &[MethodInfo],
    reference: Option<&MethodInfo>,
    standings: &[ranking::Standing],
    views: usize,
) -> Vec<Fact> {
    let with_figures = rows.iter().filter(|r| r.metrics.is_some()).count();
    let failed = rows.iter().filter(|r| r.error.is_some()).count();
    let count = |f: &dyn Fn(&Row) -> String| {
        let mut v: Vec<String> = rows.iter().map(f).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    let mut facts = Vec::new();
    if let Some(v) = ranking::verdict(standings, views, catalog) {
        facts.push(Fact::new("winner", v));
    }
    facts.extend([
        Fact::new(
            "rows",
            format!(
                "{} ({with_figures} with figures, {failed} failed, {} without ground truth)",
                rows.len(),
                rows.len() - with_figures - failed
            ),
        ),
        Fact::new("datasets", stats.datasets.join(", ")),
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
        Fact::new("cells", stats.cells.len().to_string()),
        Fact::new(
            "paired comparisons",
            match reference {
                Some(r) => format!("{} − every other label, on identical inputs", r.label),
                None => "none (no full SMSfP label to compare from)".to_string(),
            },
        ),
    ]);
    if !stats.axes.is_empty() {
        let swept: Vec<String> = stats.axes.iter().map(|a| axes::label(&a.axis)).collect();
        facts.push(Fact::new("swept axes", swept.join(", ")));
    }
    facts
}

/// The provenance list and the crate versions of `provenance.json`.
fn provenance_facts(provenance: Option<&Provenance>) -> (Vec<Fact>, Vec<Fact>) {
    let mut facts = Vec::new();
    let mut crates = Vec::new();
    match provenance {
        Some(p) => {
            let or_unknown = |v: &Option<String>| v.clone().unwrap_or_else(|| "unknown".into());
            facts.push(Fact::new("version", or_unknown(&p.version)));
            facts.push(Fact::new("commit", or_unknown(&p.commit)));
            facts.push(Fact::new("CPU", or_unknown(&p.cpu)));
            facts.push(Fact::new("threads", or_unknown(&p.threads)));
            facts.push(Fact::new("started", or_unknown(&p.started)));
            crates = p
                .crates
                .iter()
                .map(|(k, v)| Fact::new(k.clone(), v.clone()))
                .collect();
        }
        None => facts.push(Fact::new("provenance", "unknown (no provenance.json)")),
    }
    (facts, crates)
}
