//! Rendering through the templates of `benchmarks/templates/` (compiled
//! in): the code builds plain data, the templates say how it looks and what
//! it means. The report's pages (`index.html`, `report.md`) take one
//! [`Context`]; the explanatory text both share is in `text.jinja`,
//! compiled in front of each. The summaries of runs over views
//! (`summary.md`, `demo.md`) are [`document`]s. HTML escaping is the
//! template engine's (automatic for `.html`).

use super::grids::Grid;
use super::plots::Plot;
use super::tables::Table;
use serde::Serialize;
use sfp_core::{Error, Result};

const TEXT: &str = include_str!("../../templates/text.jinja");
const HTML: &str = include_str!("../../templates/index.html");
const MARKDOWN: &str = include_str!("../../templates/report.md");

/// A table with its markdown rendering (the markdown template prints it).
#[derive(Clone, Debug, Serialize)]
pub struct Shown {
    #[serde(flatten)]
    pub table: Table,
    pub markdown: String,
}

impl From<Table> for Shown {
    fn from(table: Table) -> Shown {
        let markdown = table.markdown();
        Shown { table, markdown }
    }
}

/// A `name: value` line of the overview and provenance lists.
#[derive(Clone, Debug, Serialize)]
pub struct Fact {
    pub name: String,
    pub value: String,
}

impl Fact {
    pub fn new(name: impl Into<String>, value: impl Into<String>) -> Fact {
        Fact {
            name: name.into(),
            value: value.into(),
        }
    }
}

/// A titled group of plots (one swept axis).
#[derive(Clone, Debug, Serialize)]
pub struct PlotGroup {
    pub axis: String,
    pub plots: Vec<Plot>,
}

/// Everything the templates show.
#[derive(Clone, Debug, Serialize)]
pub struct Context {
    /// Bootstrap resamples per interval (the text says how many).
    pub resamples: usize,
    pub overview: Vec<Fact>,
    /// Whether any axis is swept (else there is no robustness section).
    pub swept: bool,
    /// Tables in reading order (Table 1, per object, Table 2, paired).
    pub tables: Vec<Shown>,
    pub plot_groups: Vec<PlotGroup>,
    pub grids: Vec<Grid>,
    /// `sheet.png` beside the report (the demo's contact sheet of every
    /// view and method), when there is one.
    pub sheet: Option<String>,
    pub missing_pictures: Vec<String>,
    /// Tables after the pictures (every cell, rows without figures, times).
    pub details: Vec<Shown>,
    pub sweep_toml: Option<String>,
    pub provenance: Vec<Fact>,
    pub crates: Vec<Fact>,
    pub notes: Vec<String>,
}

/// Renders the template `source` (named `name`) with `context`: block tags
/// take their line with them; the last newline is kept when
/// `keep_trailing_newline`.
fn render(
    name: &str,
    source: &str,
    context: &impl Serialize,
    keep_trailing_newline: bool,
) -> Result<String> {
    let mut env = minijinja::Environment::new();
    env.set_syntax(
        minijinja::syntax::SyntaxConfig::builder()
            .trim_blocks(true)
            .lstrip_blocks(true)
            .keep_trailing_newline(keep_trailing_newline)
            .build()
            .map_err(|e| Error::invalid(format!("report template syntax: {e}")))?,
    );
    let template = env
        .template_from_named_str(name, source)
        .map_err(|e| Error::invalid(format!("report template {name}: {e}")))?;
    template
        .render(minijinja::Value::from(minijinja::value::Serde(context)))
        .map_err(|e| Error::invalid(format!("report template {name}: {e}")))
}

/// `index.html`.
pub fn html(context: &Context) -> Result<String> {
    render("index.html", &format!("{TEXT}{HTML}"), context, false)
}

/// `report.md`.
pub fn markdown(context: &Context) -> Result<String> {
    render("report.md", &format!("{TEXT}{MARKDOWN}"), context, false)
}

/// A text file (a `summary.md`) from its template in `templates/`, ending
/// as the template does.
pub fn document(name: &str, source: &str, context: &impl Serialize) -> Result<String> {
    render(name, source, context, true)
}
