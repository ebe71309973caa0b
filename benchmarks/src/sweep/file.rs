//! The sweep file (TOML, format in `benchmarks/README.md`): which views,
//! which axes, which methods and how many noise seeds. Everything is checked
//! here, before anything renders: an unknown key, axis, method or option is
//! an error naming the file and the key.

use super::axes;
use super::axes::axis::{Axis, AxisKind, Change};
use crate::row::AxisValue;
use serde::Deserialize;
use sfp_core::analytic::Shape;
use sfp_core::{Error, Result};
use sfp_reconstruct::methods::MethodConfig;
use sfp_reconstruct::shared_options::validate_eta;
use sfp_renderer::scene::{MAX_SIDE, SensorDesc};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The most rows a sweep may plan (benchmarks/README.md): each row costs a
/// reconstruction, and a plan beyond it would exhaust the memory before
/// the first row.
pub const MAX_ROWS: usize = 1_000_000;

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
    pub config: MethodConfig,
    pub eta: MethodEta,
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
            .map(|(i, m)| method(m).map_err(|e| err(&format!("methods[{i}]"), e)))
            .collect::<Result<Vec<_>>>()?;
        for (i, m) in methods.iter().enumerate() {
            if methods[..i].iter().any(|p| p.label == m.label) {
                return Err(err(
                    &format!("methods[{i}].label"),
                    format!(
                        "{:?} is used twice (give each entry its own `label`)",
                        m.label
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
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-.".contains(c);
    if dataset.is_empty() || !dataset.chars().all(safe) || dataset.starts_with('.') {
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
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-.".contains(c);
    if label.is_empty() || !label.chars().all(safe) || label.starts_with('.') {
        return Err(format!(
            "label {label:?}: use letters, digits, `_`, `-` and `.` only"
        ));
    }
    let eta = if options.get("eta").and_then(|e| e.as_str()) == Some("true") {
        options.remove("eta");
        MethodEta::True
    } else {
        MethodEta::Configured
    };
    let config = MethodConfig::with_options(&name, options).map_err(|e| e.to_string())?;
    Ok(MethodSpec { label, config, eta })
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
