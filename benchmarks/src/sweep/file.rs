//! The sweep file (TOML, format in `benchmarks/README.md`): which views,
//! which axes, which methods and how many noise seeds. Everything is checked
//! here, before anything renders: an unknown key, axis, method or option is
//! an error naming the file and the key.

use super::axes;
use super::axes::axis::{Axis, AxisKind, Change};
use super::command_method::CommandMethod;
use super::oracle::{self, Oracle};
use crate::row::AxisValue;
use serde::Deserialize;
use sfp_core::analytic::Shape;
use sfp_core::prediction::Axes;
use sfp_core::{Error, Result};
use sfp_reconstruct::methods::{METHODS, MethodConfig};
use sfp_reconstruct::shared_options::validate_eta;
use sfp_renderer::scene::{MAX_SIDE, SensorDesc};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The most rows a sweep may plan (benchmarks/README.md): each row costs a
/// reconstruction, and a plan beyond it would exhaust the memory before
/// the first row.
pub const MAX_ROWS: usize = 1_000_000;

/// A command method's time limit when its entry gives none, seconds.
pub const DEFAULT_TIMEOUT_S: f64 = 600.0;

/// Which rows keep their method's result folder (pictures).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pictures {
    /// Seed 0 at each view's first value of every axis, every method.
    #[default]
    First,
    /// Every row of seed 0.
    Seed0,
    None,
}

/// A sweep file's content. Field names are the file's keys.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepDesc {
    /// Noise seeds `0..seeds` per (view, axis values, method).
    #[serde(default = "one")]
    seeds: u64,
    #[serde(default)]
    pictures: Pictures,
    views: Vec<ViewsDesc>,
    #[serde(default)]
    axes: toml::Table,
    /// Replaces the views' own sensor for the exposures.
    #[serde(default)]
    sensor: Option<SensorDesc>,
    methods: Vec<toml::Table>,
}

fn one() -> u64 {
    1
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewsDesc {
    preset: Option<String>,
    scene: Option<PathBuf>,
    analytic: Option<Shape>,
    folder: Option<PathBuf>,
    /// Group name in the results (default: the preset, `analytic`, `scene`
    /// or the folder's name).
    name: Option<String>,
    size: Option<usize>,
    spp: Option<u32>,
    /// Views per object (presets).
    views: Option<usize>,
    /// Only these objects of the preset.
    objects: Option<Vec<String>>,
    /// The preset's objects with their spatially varying materials (as
    /// `sfp dataset --svbrdf`).
    svbrdf: Option<bool>,
    /// The preset's render seed (as `sfp dataset --seed`): other poses,
    /// and for `glossy` other materials and lighting, to hold views out.
    seed: Option<u64>,
}

/// Where a group of views comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SourceKind {
    Preset {
        preset: String,
        size: Option<usize>,
        spp: Option<u32>,
        views: Option<usize>,
        objects: Option<Vec<String>>,
        /// Objects get their SVBRDF materials (`[dataset] svbrdf`).
        svbrdf: bool,
        /// Render seed (`[render] seed`), when not the preset's.
        seed: Option<u64>,
    },
    Scene {
        path: PathBuf,
        size: Option<usize>,
        spp: Option<u32>,
    },
    Analytic {
        shape: Shape,
        size: usize,
    },
    /// Existing views, used as stored: no render, one exposure (seed 0).
    Folder {
        path: PathBuf,
    },
}

/// One `[[views]]` entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// Group name of its views in the results (`Row::dataset`).
    pub dataset: String,
    pub kind: SourceKind,
}

/// How a method's assumed η is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MethodEta {
    /// As configured (the method's default or the file's `eta`).
    Configured,
    /// The view's true η.
    True,
}

/// One `[[methods]]` entry.
#[derive(Clone, Debug)]
pub struct MethodSpec {
    /// Name in the results (`Row::method`), unique in the sweep.
    pub label: String,
    pub runner: Runner,
    /// Always `Configured` for a command method.
    pub eta: MethodEta,
}

/// What a `[[methods]]` entry (or a planned row) runs.
// The registered variant is as large as the configuration rows always held
// inline; boxing it would allocate once per planned row for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Runner {
    /// A registered method with its configuration (`method = …`).
    Registered(MethodConfig),
    /// One's own program (`command = […]`).
    Command(CommandMethod),
    /// A per-pixel oracle (`oracle = "mixed"`).
    Oracle(Oracle),
}

impl Runner {
    /// The configuration rows record (`Row::config`) and row keys hash.
    pub fn to_value(&self) -> serde_json::Value {
        match self {
            Runner::Registered(config) => config.to_value(),
            Runner::Command(command) => command.to_value(),
            Runner::Oracle(oracle) => {
                serde_json::json!({ "oracle": oracle.model.name(), "eta": oracle.eta })
            }
        }
    }
}

/// A validated sweep file.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub path: PathBuf,
    /// The file verbatim (copied to `DIR/sweep.toml`).
    pub text: String,
    pub seeds: u64,
    pub pictures: Pictures,
    pub sources: Vec<Source>,
    /// Axis name → values, in the file's order of values.
    pub axes: BTreeMap<String, Vec<AxisValue>>,
    pub sensor: Option<SensorDesc>,
    pub methods: Vec<MethodSpec>,
    /// What the file should change though it is read (deprecated keys).
    pub notes: Vec<String>,
}

impl Sweep {
    /// Reads and validates a sweep file.
    pub fn load(path: &Path) -> Result<Sweep> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::read(path, e))?;
        Sweep::from_toml(&text, path)
    }

    /// Parses sweep text as if read from `path` (which names errors and
    /// anchors relative `scene` and `folder` paths).
    pub fn from_toml(text: &str, path: &Path) -> Result<Sweep> {
        let err = |key: &str, message: String| Error::file(path, format!("`{key}`: {message}"));
        let desc: SweepDesc = toml::from_str(text)
            .map_err(|e| Error::file(path, e.to_string().trim_end().to_string()))?;
        if desc.seeds == 0 {
            return Err(err("seeds", "must be at least 1".into()));
        }
        if desc.views.is_empty() {
            return Err(err("views", "the sweep has no [[views]]".into()));
        }
        if desc.methods.is_empty() {
            return Err(err("methods", "the sweep has no [[methods]]".into()));
        }
        if let Some(sensor) = &desc.sensor {
            sensor
                .check()
                .map_err(|(key, m)| err(&format!("sensor.{key}"), m.into()))?;
        }
        let anchor = path.parent().unwrap_or(Path::new("."));
        let sources = desc
            .views
            .iter()
            .enumerate()
            .map(|(i, v)| source(v, anchor).map_err(|m| err(&format!("views[{i}]"), m)))
            .collect::<Result<Vec<_>>>()?;
        let mut axes = BTreeMap::new();
        let mut notes = Vec::new();
        for (name, values) in &desc.axes {
            let key = format!("axes.{name}");
            let Some((axis, old)) = axes::named(name) else {
                return Err(err(
                    &key,
                    format!("unknown axis (known: {})", axes::keys().join(", ")),
                ));
            };
            if old {
                notes.push(format!(
                    "{}: `{key}` is now `axes.{}` (the old name is deprecated)",
                    path.display(),
                    axis.key
                ));
            }
            let values = axis_values(axis, values).map_err(|m| err(&key, m))?;
            if axes.insert(axis.key.to_string(), values).is_some() {
                return Err(err(
                    &key,
                    format!("`axes.{}` is given twice, by two names", axis.key),
                ));
            }
        }
        // Counted before planning: a plan of 10^18 rows aborted on memory.
        let per_view = rows_per_view(&axes, desc.seeds, desc.methods.len());
        if per_view > MAX_ROWS as f64 {
            return Err(err(
                "axes",
                format!(
                    "the sweep has {per_view:.3e} rows per view (axis values × seeds × methods), \
                     more than the limit of {MAX_ROWS}: split it into several sweeps"
                ),
            ));
        }
        for (i, s) in sources.iter().enumerate() {
            for name in axes.keys() {
                if !applies(name, &s.kind) {
                    return Err(err(
                        &format!("axes.{name}"),
                        format!(
                            "does not apply to views[{i}] ({}){}",
                            describe(&s.kind),
                            match s.kind {
                                SourceKind::Folder { .. } =>
                                    ": stored views are used as they are (run them in a sweep of their own)",
                                _ => "",
                            }
                        ),
                    ));
                }
            }
        }
        let methods = desc
            .methods
            .iter()
            .enumerate()
            .map(|(i, m)| {
                if is_command(m) {
                    command_method(m, anchor)
                        .map_err(|(key, e)| err(&format!("methods[{i}].{key}"), e))
                } else if m.contains_key("oracle") {
                    oracle_entry(m).map_err(|(key, e)| err(&format!("methods[{i}].{key}"), e))
                } else {
                    method(m).map_err(|e| err(&format!("methods[{i}]"), e))
                }
            })
            .collect::<Result<Vec<_>>>()?;
        for (i, m) in methods.iter().enumerate() {
            let key = match m.runner {
                Runner::Registered(_) | Runner::Oracle(_) => "label",
                Runner::Command(_) => "name",
            };
            if methods[..i].iter().any(|p| p.label == m.label) {
                return Err(err(
                    &format!("methods[{i}].{key}"),
                    format!(
                        "{:?} is used twice (give each entry its own `{key}`)",
                        m.label
                    ),
                ));
            }
            if let (Runner::Command(_), Some(name)) = (&m.runner, method_axis(&axes)) {
                return Err(err(
                    &format!("methods[{i}].command"),
                    format!(
                        "the `axes.{name}` axis changes a built-in method's options, which a \
                         command does not have: sweep it without command methods"
                    ),
                ));
            }
            for name in axes.keys() {
                let axis = axes::axis(name).expect("a known axis");
                if let Change::Method { option, .. } = axis.change
                    && desc.methods[i].contains_key(option)
                {
                    return Err(err(
                        &format!("methods[{i}].{option}"),
                        format!("is set by the `{name}` axis; leave it out"),
                    ));
                }
            }
        }
        check_true_eta(&axes, &methods).map_err(|(key, m)| err(&key, m))?;
        Ok(Sweep {
            path: path.to_path_buf(),
            text: text.to_string(),
            seeds: desc.seeds,
            pictures: desc.pictures,
            sources,
            axes,
            sensor: desc.sensor,
            methods,
            notes,
        })
    }

    /// Rows each view of the sweep adds to the plan (as a float: it may be
    /// beyond any integer before it is refused).
    pub fn rows_per_view(&self) -> f64 {
        rows_per_view(&self.axes, self.seeds, self.methods.len())
    }

    /// The axes of one kind, in name order.
    pub fn axes_of(&self, kind: AxisKind) -> Vec<(&str, &[AxisValue])> {
        self.axes
            .iter()
            .filter(|(name, _)| axes::axis(name).is_some_and(|a| a.kind() == kind))
            .map(|(n, v)| (n.as_str(), v.as_slice()))
            .collect()
    }
}

/// A method given the view's true η takes each value of the `eta` axis:
/// each must be an η a method accepts, refused here rather than when the
/// plan meets it.
fn check_true_eta(
    axes: &BTreeMap<String, Vec<AxisValue>>,
    methods: &[MethodSpec],
) -> std::result::Result<(), (String, String)> {
    let Some(etas) = axes.get(axes::material::ETA.key) else {
        return Ok(());
    };
    let by_axis = axes
        .get(axes::method::METHOD_ETA.key)
        .is_some_and(|v| v.contains(&AxisValue::Text("true".into())));
    let Some(taker) = methods
        .iter()
        .position(|m| m.eta == MethodEta::True)
        .map(|i| format!("methods[{i}] (`eta = \"true\"`)"))
        .or(by_axis.then(|| format!("the `{}` value \"true\"", axes::method::METHOD_ETA.key)))
    else {
        return Ok(());
    };
    for eta in etas {
        if let AxisValue::Number(x) = eta
            && let Err(e) = validate_eta(*x)
        {
            return Err((
                "axes.eta".into(),
                format!("{x} would be the η assumed by {taker}: {e}"),
            ));
        }
    }
    Ok(())
}

/// The first method axis of the sweep, if any.
fn method_axis(axes: &BTreeMap<String, Vec<AxisValue>>) -> Option<&str> {
    axes.keys()
        .find(|name| axes::axis(name).is_some_and(|a| a.kind() == AxisKind::Method))
        .map(String::as_str)
}

fn rows_per_view(axes: &BTreeMap<String, Vec<AxisValue>>, seeds: u64, methods: usize) -> f64 {
    axes.values().map(|v| v.len() as f64).product::<f64>() * seeds as f64 * methods as f64
}

fn source(v: &ViewsDesc, anchor: &Path) -> std::result::Result<Source, String> {
    let given = [
        v.preset.is_some(),
        v.scene.is_some(),
        v.analytic.is_some(),
        v.folder.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err("give exactly one of `preset`, `scene`, `analytic` or `folder`".into());
    }
    let only = |key: &str, set: bool, allowed: bool| {
        if set && !allowed {
            Err(format!("`{key}` does not apply to this kind of views"))
        } else {
            Ok(())
        }
    };
    let rendered = v.preset.is_some() || v.scene.is_some();
    only("size", v.size.is_some(), v.folder.is_none())?;
    only("spp", v.spp.is_some(), rendered)?;
    only("views", v.views.is_some(), v.preset.is_some())?;
    only("objects", v.objects.is_some(), v.preset.is_some())?;
    only("svbrdf", v.svbrdf.is_some(), v.preset.is_some())?;
    only("seed", v.seed.is_some(), v.preset.is_some())?;
    if v.size == Some(0) || v.spp == Some(0) || v.views == Some(0) {
        return Err("`size`, `spp` and `views` must be at least 1".into());
    }
    if v.size.is_some_and(|s| s > MAX_SIDE) {
        return Err(format!("`size` must be at most {MAX_SIDE}"));
    }
    if v.views.is_some_and(|n| n > MAX_ROWS) {
        return Err(format!("`views` must be at most {MAX_ROWS}"));
    }
    if v.objects.as_ref().is_some_and(Vec::is_empty) {
        return Err(
            "`objects = []` selects no object: name some, or leave `objects` out for all".into(),
        );
    }
    let (default_name, kind) = if let Some(preset) = &v.preset {
        (
            preset.clone(),
            SourceKind::Preset {
                preset: preset.clone(),
                size: v.size,
                spp: v.spp,
                views: v.views,
                objects: v.objects.clone(),
                svbrdf: v.svbrdf.unwrap_or(false),
                seed: v.seed,
            },
        )
    } else if let Some(scene) = &v.scene {
        (
            "scene".to_string(),
            SourceKind::Scene {
                path: anchor.join(scene),
                size: v.size,
                spp: v.spp,
            },
        )
    } else if let Some(shape) = v.analytic {
        (
            "analytic".to_string(),
            SourceKind::Analytic {
                shape,
                size: v.size.unwrap_or(128),
            },
        )
    } else {
        let path = anchor.join(v.folder.as_ref().expect("one source is given"));
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "folder".into());
        (name, SourceKind::Folder { path })
    };
    let dataset = v.name.clone().unwrap_or(default_name);
    if !is_safe_name(&dataset) {
        return Err(format!(
            "group name {dataset:?}: use letters, digits, `_`, `-` and `.` only (set `name`)"
        ));
    }
    Ok(Source { dataset, kind })
}

fn describe(kind: &SourceKind) -> String {
    match kind {
        SourceKind::Preset { preset, .. } => format!("preset {preset:?}"),
        SourceKind::Scene { path, .. } => format!("scene {}", path.display()),
        SourceKind::Analytic { .. } => "an analytic view".into(),
        SourceKind::Folder { path } => format!("stored views in {}", path.display()),
    }
}

/// Whether axis `name` can change views of `kind`.
fn applies(name: &str, kind: &SourceKind) -> bool {
    let axis = axes::axis(name).expect("a known axis");
    match kind {
        SourceKind::Preset { .. } | SourceKind::Scene { .. } => true,
        SourceKind::Analytic { .. } => match axis.change {
            Change::Render { analytic, .. } => analytic.is_some(),
            Change::Noise(_) | Change::Method { .. } => true,
        },
        SourceKind::Folder { .. } => axis.kind() == AxisKind::Method,
    }
}

fn axis_values(axis: &Axis, values: &toml::Value) -> std::result::Result<Vec<AxisValue>, String> {
    let meaning = axis.meaning;
    let list = values
        .as_array()
        .filter(|l| !l.is_empty())
        .ok_or_else(|| format!("expected a non-empty list of values, each {meaning}"))?;
    let mut out: Vec<AxisValue> = Vec::with_capacity(list.len());
    for v in list {
        let value = match v {
            toml::Value::Integer(i) => AxisValue::Number(*i as f64),
            toml::Value::Float(f) => AxisValue::Number(*f),
            toml::Value::String(s) => AxisValue::Text(s.clone()),
            other => return Err(format!("{other} is not {meaning}")),
        };
        if !(axis.accepts)(&value) {
            return Err(format!("{v} is not {meaning}"));
        }
        if out.contains(&value) {
            return Err(format!("{v} is listed twice"));
        }
        out.push(value);
    }
    Ok(out)
}

fn method(table: &toml::Table) -> std::result::Result<MethodSpec, String> {
    let mut options = match serde_json::to_value(table) {
        Ok(serde_json::Value::Object(map)) => map,
        _ => return Err("not a table of method options".into()),
    };
    let name = match options.remove("method") {
        Some(serde_json::Value::String(name)) => name,
        _ => return Err("`method` (a method name) is missing".into()),
    };
    let label = match options.remove("label") {
        Some(serde_json::Value::String(label)) => label,
        None => name.clone(),
        Some(other) => return Err(format!("`label` must be text, not {other}")),
    };
    let label = safe_label(label)?;
    let eta = if options.get("eta").and_then(|e| e.as_str()) == Some("true") {
        options.remove("eta");
        MethodEta::True
    } else {
        MethodEta::Configured
    };
    let config = MethodConfig::with_options(&name, options).map_err(|e| e.to_string())?;
    Ok(MethodSpec {
        label,
        runner: Runner::Registered(config),
        eta,
    })
}

/// An oracle's entry (`oracle`), or the key at fault and why.
fn oracle_entry(table: &toml::Table) -> std::result::Result<MethodSpec, (String, String)> {
    let (label, oracle) = oracle::parse(table)?;
    let label = safe_label(label).map_err(|e| ("label".to_string(), e))?;
    Ok(MethodSpec {
        label,
        runner: Runner::Oracle(oracle),
        eta: MethodEta::Configured,
    })
}

/// The keys of a command method's entry.
const COMMAND_KEYS: [&str; 4] = ["name", "command", "axes", "timeout_s"];

/// Whether a `[[methods]]` entry is one's own command (it has `command`
/// or `name`) rather than a registered method.
fn is_command(table: &toml::Table) -> bool {
    table.contains_key("command") || table.contains_key("name")
}

/// A command method's entry (`anchor`: the sweep file's folder, where it
/// runs), or the key at fault and why.
fn command_method(
    table: &toml::Table,
    anchor: &Path,
) -> std::result::Result<MethodSpec, (String, String)> {
    let bad = |key: &str, message: String| (key.to_string(), message);
    if let Some(key) = table.keys().find(|k| !COMMAND_KEYS.contains(&k.as_str())) {
        return Err(bad(
            key,
            format!(
                "is not a key of a command method (it has {}; `method` and its options are a \
                 built-in method's)",
                COMMAND_KEYS.map(|k| format!("`{k}`")).join(", ")
            ),
        ));
    }
    let name = match table.get("name") {
        Some(toml::Value::String(name)) => name.clone(),
        Some(other) => return Err(bad("name", format!("must be text, not {other}"))),
        None => return Err(bad("name", "is missing: name your method".into())),
    };
    if !is_safe_name(&name) {
        return Err(bad(
            "name",
            format!("{name:?}: use letters, digits, `_`, `-` and `.` only"),
        ));
    }
    if METHODS.contains(&name.as_str()) {
        return Err(bad(
            "name",
            format!("{name:?} is a built-in method's name: give your method another"),
        ));
    }
    let command: Vec<String> = match table.get("command") {
        Some(toml::Value::Array(list)) => list
            .iter()
            .map(|v| v.as_str().map(str::to_string))
            .collect::<Option<_>>()
            .ok_or_else(|| bad("command", "must be an array of strings".into()))?,
        Some(other) => {
            return Err(bad(
                "command",
                format!(
                    "must be an array of strings (the program, then its arguments), not {other}"
                ),
            ));
        }
        None => return Err(bad("command", "is missing: the program to run".into())),
    };
    if command.first().is_none_or(String::is_empty) {
        return Err(bad(
            "command",
            "is empty: give the program, then its arguments (`{view}` and `{out}` are replaced \
             by the row's folders)"
                .into(),
        ));
    }
    let axes = match table.get("axes") {
        None => Axes::Ours,
        Some(value) => value.as_str().and_then(Axes::parse).ok_or_else(|| {
            bad(
                "axes",
                format!("{value} is not one of {}", Axes::NAMES.join(", ")),
            )
        })?,
    };
    let timeout_s = match table.get("timeout_s") {
        None => DEFAULT_TIMEOUT_S,
        Some(toml::Value::Integer(i)) => *i as f64,
        Some(toml::Value::Float(f)) => *f,
        Some(other) => {
            return Err(bad(
                "timeout_s",
                format!("{other} is not a number of seconds"),
            ));
        }
    };
    if !(timeout_s > 0.0 && std::time::Duration::try_from_secs_f64(timeout_s).is_ok()) {
        return Err(bad(
            "timeout_s",
            format!("{timeout_s} is not a positive number of seconds"),
        ));
    }
    let anchor = if anchor.as_os_str().is_empty() {
        Path::new(".")
    } else {
        anchor
    };
    let dir = std::path::absolute(anchor)
        .map_err(|e| bad("command", format!("{}: {e}", anchor.display())))?;
    Ok(MethodSpec {
        label: name,
        runner: Runner::Command(CommandMethod {
            command,
            axes,
            timeout_s,
            dir,
        }),
        eta: MethodEta::Configured,
    })
}

/// A group or method name that is safe as a folder name and a CSV cell:
/// letters, digits, `_`, `-` and `.`, not starting with `.`.
/// `label` when it can name a result folder, or why not.
fn safe_label(label: String) -> std::result::Result<String, String> {
    if is_safe_name(&label) {
        Ok(label)
    } else {
        Err(format!(
            "label {label:?}: use letters, digits, `_`, `-` and `.` only"
        ))
    }
}

fn is_safe_name(name: &str) -> bool {
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-.".contains(c);
    !name.is_empty() && name.chars().all(safe) && !name.starts_with('.')
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = r#"
seeds = 2

[[views]]
analytic = "sphere"
size = 32

[axes]
eta = [1.3, 1.5]

[[methods]]
method = "smith"

[[methods]]
label = "smith-true-eta"
method = "smith"
eta = "true"
"#;

    fn parse(text: &str) -> Result<Sweep> {
        Sweep::from_toml(text, Path::new("/sweeps/test.toml"))
    }

    #[test]
    fn a_sweep_parses() {
        let s = parse(BASE).unwrap();
        assert_eq!(s.seeds, 2);
        assert_eq!(s.methods[1].label, "smith-true-eta");
        assert_eq!(s.methods[1].eta, MethodEta::True);
        assert_eq!(s.methods[0].label, "smith");
        assert_eq!(
            s.axes["eta"],
            [AxisValue::Number(1.3), AxisValue::Number(1.5)]
        );
        assert_eq!(s.sources[0].dataset, "analytic");
    }

    #[test]
    fn a_command_method_parses_with_its_defaults() {
        let mine =
            "[[methods]]\nname = \"mine\"\ncommand = [\"./predict.sh\", \"{view}\", \"{out}\"]\n";
        let s = parse(&format!("{BASE}{mine}")).unwrap();
        let Runner::Command(c) = &s.methods[2].runner else {
            panic!("{:?}", s.methods[2])
        };
        assert_eq!(s.methods[2].label, "mine");
        assert_eq!(c.command, ["./predict.sh", "{view}", "{out}"]);
        assert_eq!((c.axes, c.timeout_s), (Axes::Ours, DEFAULT_TIMEOUT_S));
        assert_eq!(c.dir, Path::new("/sweeps"));
        let s = parse(&format!("{BASE}{mine}axes = \"opencv\"\ntimeout_s = 2.5\n")).unwrap();
        let Runner::Command(c) = &s.methods[2].runner else {
            panic!("{:?}", s.methods[2])
        };
        assert_eq!((c.axes, c.timeout_s), (Axes::Opencv, 2.5));
        assert_eq!(
            s.methods[2].runner.to_value(),
            serde_json::json!({
                "command": ["./predict.sh", "{view}", "{out}"],
                "axes": "opencv",
                "timeout_s": 2.5,
            })
        );
    }

    #[test]
    fn the_old_specular_key_is_read_with_a_note() {
        let text = BASE
            .replace("analytic = \"sphere\"", "preset = \"builtin\"")
            .replace("eta = [1.3, 1.5]", "specular = [0.0, 0.3]");
        let s = parse(&text).unwrap();
        assert_eq!(s.axes.keys().collect::<Vec<_>>(), ["specular_weight"]);
        assert_eq!(s.notes.len(), 1);
        assert!(
            s.notes[0].contains("test.toml") && s.notes[0].contains("axes.specular_weight"),
            "{:?}",
            s.notes
        );
        assert!(
            parse(&text.replace("specular = ", "specular_weight = "))
                .unwrap()
                .notes
                .is_empty()
        );
        let both = text.replace(
            "specular = [0.0, 0.3]",
            "specular = [0.0]\nspecular_weight = [0.3]",
        );
        let err = parse(&both).unwrap_err().to_string();
        assert!(err.contains("given twice"), "{err}");
    }

    #[test]
    fn errors_name_the_file_and_the_key() {
        let cases = [
            (BASE.replace("eta = [1.3", "etta = [1.3"), "axes.etta"),
            (BASE.replace("seeds = 2", "seeds = 2\nseed = 1"), "seed"),
            (
                BASE.replace(
                    "method = \"smith\"\n\n",
                    "method = \"smith\"\nlamda = 1\n\n",
                ),
                "lamda",
            ),
            (BASE.replace("\"smith\"\n\n", "\"smiht\"\n\n"), "smiht"),
            // Option values out of range, as the method's own check says.
            (
                BASE.replace(
                    "method = \"smith\"\n\n",
                    "method = \"smith\"\nlambda = -1\n\n",
                ),
                "lambda",
            ),
            (
                BASE.replace(
                    "method = \"smith\"\n\n",
                    "method = \"smith\"\neta = 3.5\n\n",
                ),
                "eta = 3.5",
            ),
            (
                BASE.replace("eta = [1.3, 1.5]", "method_eta = [3.5]")
                    .replace("eta = \"true\"\n", ""),
                "axes.method_eta",
            ),
            // A true η of 1 the `eta = "true"` method would assume.
            (
                BASE.replace("eta = [1.3, 1.5]", "eta = [1.0, 1.5]"),
                "axes.eta",
            ),
            (
                BASE.replace("eta = [1.3, 1.5]", "specular_weight = [0.0, 0.3]"),
                "axes.specular_weight",
            ),
            (
                BASE.replace("eta = [1.3, 1.5]", "eta = [1.3, 1.3]"),
                "axes.eta",
            ),
            (
                BASE.replace("eta = [1.3, 1.5]", "light = [\"disco\"]"),
                "axes.light",
            ),
            (
                BASE.replace("eta = [1.3, 1.5]", "method_eta = [1.5]"),
                "methods[1].eta",
            ),
            (
                BASE.replace(
                    "analytic = \"sphere\"",
                    "analytic = \"sphere\"\npreset = \"a\"",
                ),
                "views[0]",
            ),
            (
                BASE.replace("analytic = \"sphere\"", "analytic = \"cube\""),
                "cube",
            ),
            (
                BASE.replace(
                    "analytic = \"sphere\"",
                    "analytic = \"sphere\"\nsvbrdf = true",
                ),
                "svbrdf",
            ),
            (
                BASE.replace("label = \"smith-true-eta\"\n", ""),
                "methods[1].label",
            ),
            // Out-of-range sensors, sizes, selections and plans.
            (format!("{BASE}[sensor]\nbits = 40\n"), "sensor.bits"),
            (
                format!("{BASE}[sensor]\nfull_well = 0\n"),
                "sensor.full_well",
            ),
            (BASE.replace("size = 32", "size = 100000"), "size"),
            (
                BASE.replace(
                    "analytic = \"sphere\"\nsize = 32",
                    "preset = \"builtin\"\nobjects = []",
                ),
                "objects = []",
            ),
            (
                BASE.replace("seeds = 2", "seeds = 1000000000000000000"),
                "limit of 1000000",
            ),
            (
                BASE.replace(
                    "eta = [1.3, 1.5]",
                    &(0..6)
                        .map(|i| {
                            let values: Vec<String> = (1..=100)
                                .map(|v| format!("{}", 1.0 + v as f64 / 1000.0))
                                .collect();
                            let axis = [
                                "eta",
                                "noise_read_sigma",
                                "noise_full_well",
                                "specular_weight",
                                "light_elevation_deg",
                                "light_azimuth_deg",
                            ][i];
                            format!("{axis} = [{}]", values.join(", "))
                        })
                        .collect::<Vec<_>>()
                        .join("\n"),
                ),
                "limit of 1000000",
            ),
            (
                BASE.replace("analytic = \"sphere\"\nsize = 32", "folder = \"views\""),
                "axes.eta",
            ),
            // Command methods: each key checked, the name one of its own.
            (
                format!("{BASE}[[methods]]\nname = \"mine\"\ncommand = []\n"),
                "methods[2].command",
            ),
            (
                format!("{BASE}[[methods]]\nname = \"mine\"\ncommand = [\"a\", 1]\n"),
                "methods[2].command",
            ),
            (
                format!("{BASE}[[methods]]\nname = \"mine\"\n"),
                "methods[2].command",
            ),
            (
                format!("{BASE}[[methods]]\ncommand = [\"predict\"]\n"),
                "methods[2].name",
            ),
            (
                format!("{BASE}[[methods]]\nname = \"smith\"\ncommand = [\"predict\"]\n"),
                "methods[2].name",
            ),
            (
                format!("{BASE}[[methods]]\nname = \"smith-true-eta\"\ncommand = [\"predict\"]\n"),
                "methods[2].name",
            ),
            (
                format!("{BASE}[[methods]]\nname = \"../x\"\ncommand = [\"predict\"]\n"),
                "methods[2].name",
            ),
            (
                format!(
                    "{BASE}[[methods]]\nname = \"mine\"\ncommand = [\"predict\"]\naxes = \"up\"\n"
                ),
                "methods[2].axes",
            ),
            (
                format!(
                    "{BASE}[[methods]]\nname = \"mine\"\ncommand = [\"predict\"]\ntimeout_s = 0\n"
                ),
                "methods[2].timeout_s",
            ),
            (
                format!(
                    "{BASE}[[methods]]\nname = \"mine\"\ncommand = [\"predict\"]\nmethod = \"smith\"\n"
                ),
                "methods[2].method",
            ),
            (
                format!("{BASE}[[methods]]\nname = \"mine\"\ncommand = [\"predict\"]\n")
                    .replace("eta = [1.3, 1.5]", "method_eta = [1.5]")
                    .replace("eta = \"true\"\n", ""),
                "methods[2].command",
            ),
        ];
        for (text, key) in cases {
            let err = parse(&text).expect_err(key).to_string();
            assert!(
                err.contains("test.toml") && err.contains(key),
                "{key}: {err}"
            );
        }
    }
}
