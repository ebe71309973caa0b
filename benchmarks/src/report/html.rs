//! Rendering the report's content through its templates
//! (`benchmarks/templates/index.html` and `report.md`, compiled in): the
//! code builds one [`Context`] of plain data, the templates say how it
//! looks and what it means (the explanatory text both pages share is in
//! `templates/text.jinja`, compiled in front of each). HTML escaping is the
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
    /// Tables in reading order (Table 1, per object, Table 2, paired).
    pub tables: Vec<Shown>,
    pub plot_groups: Vec<PlotGroup>,
    pub grids: Vec<Grid>,
    pub missing_pictures: Vec<String>,
    /// Tables after the pictures (every cell, rows without figures, times).
    pub details: Vec<Shown>,
    pub sweep_toml: Option<String>,
    pub provenance: Vec<Fact>,
    pub crates: Vec<Fact>,
    pub notes: Vec<String>,
}

fn render(name: &str, source: &str, context: &Context) -> Result<String> {
    let source = format!("{TEXT}{source}");
    let mut env = minijinja::Environment::new();
    env.set_syntax(
        minijinja::syntax::SyntaxConfig::builder()
            .trim_blocks(true)
            .lstrip_blocks(true)
            .build()
            .map_err(|e| Error::invalid(format!("report template syntax: {e}")))?,
    );
    let template = env
        .template_from_named_str(name, &source)
        .map_err(|e| Error::invalid(format!("report template {name}: {e}")))?;
    template
        .render(minijinja::Value::from(minijinja::value::Serde(context)))
        .map_err(|e| Error::invalid(format!("report template {name}: {e}")))
}

/// `index.html`.
pub fn html(context: &Context) -> Result<String> {
    render("index.html", HTML, context)
}

/// `report.md`.
pub fn markdown(context: &Context) -> Result<String> {
    render("report.md", MARKDOWN, context)
}
