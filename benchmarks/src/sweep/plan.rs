//! A sweep expanded into its rows, in the one order every run, shard and
//! merge agrees on: view → render-axis values → noise-axis values → seed →
//! `method_eta` → method (the last named varies fastest; axes of one kind
//! by name, values in the file's order).
//!
//! Rows are grouped by noise-free render ([`Group`]: one render, many rows)
//! and, inside it, by exposure ([`Exposure`]: one noisy input, every method
//! on it), so a render and a noise draw are each made once.

use super::axes;
use super::axes::axis::{AnalyticChange, AxisKind, Change, SceneChange, TrueEta};
use super::axes::material::TEXTURE;
use super::file::{MAX_ROWS, MethodEta, MethodSpec, Runner, SourceKind, Sweep};
use super::oracle::Oracle;
use crate::dataset::{self, DatasetView, Target};
use crate::row::AxisValue;
use serde_json::json;
use sfp_core::analytic::AnalyticScene;
use sfp_core::view::Meta;
use sfp_core::{Error, Result, SOFTWARE_VERSION};
use sfp_reconstruct::methods::MethodConfig;
use sfp_renderer::dataset::Dataset;
use sfp_renderer::scene::{Scene, SensorDesc};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Axis values of one row or group, by axis name.
pub type Point = BTreeMap<String, AxisValue>;

/// One view before the render axes apply.
#[derive(Clone, Debug)]
pub struct PlanView {
    pub dataset: String,
    pub view: String,
    pub object: String,
    pub origin: Origin,
}

/// How a view is made.
#[derive(Clone, Debug)]
pub enum Origin {
    /// A scene (a preset's view or a scene file) and its random stream.
    Rendered {
        scene: Box<Scene>,
        view_index: u64,
    },
    Analytic(AnalyticScene),
    /// A stored view folder, used as it is.
    Stored(PathBuf),
}

/// One noise-free view (a render with the render axes applied) and the rows
/// made from it.
#[derive(Clone, Debug)]
pub struct Group {
    /// Index into [`Plan::views`].
    pub view: usize,
    pub origin: Origin,
    /// Stable hash of everything that affects the render (`None` for stored
    /// views): the name of its cache folder.
    pub cache_key: Option<String>,
    pub exposures: Vec<Exposure>,
}

/// One noisy input: the group's noise-free Stokes exposed with `sensor` and
/// `seed` (stored views: the stored input, `sensor` is `None`).
#[derive(Clone, Debug)]
pub struct Exposure {
    pub sensor: Option<SensorDesc>,
    pub seed: u64,
    pub rows: Vec<PlannedRow>,
}

/// One row to compute.
#[derive(Clone, Debug)]
pub struct PlannedRow {
    /// Position in the whole (unsharded) plan.
    pub position: usize,
    pub key: String,
    pub axes: Point,
    /// The method's label.
    pub method: String,
    /// What runs: a registered method's configuration (with `method_eta`
    /// applied), or a command.
    pub runner: Runner,
    pub seed: u64,
    /// Result folder kept for pictures, relative to the output folder.
    pub pictures: Option<String>,
}

/// Every row of a sweep.
#[derive(Clone, Debug)]
pub struct Plan {
    pub views: Vec<PlanView>,
    pub groups: Vec<Group>,
}

impl Plan {
    /// Expands `sweep`: finds its views (loading preset meshes and stored
    /// views' `meta.json`) and checks that every axis value applies.
    pub fn new(sweep: &Sweep) -> Result<Plan> {
        let mut views: Vec<PlanView> = Vec::new();
        for i in 0..sweep.sources.len() {
            for v in source_views(sweep, i)? {
                if let Some(j) = views
                    .iter()
                    .position(|p| p.dataset == v.dataset && p.view == v.view)
                {
                    return Err(Error::file(
                        &sweep.path,
                        format!(
                            "`views[{i}]`: view {:?} of group {:?} is already in the sweep \
                             (view #{j}); give this entry another `name`",
                            v.view, v.dataset
                        ),
                    ));
                }
                views.push(v);
            }
        }
        let rows = views.len() as f64 * sweep.rows_per_view();
        if rows > MAX_ROWS as f64 {
            return Err(Error::file(
                &sweep.path,
                format!(
                    "the sweep has {rows:.3e} rows ({} views × {} rows each), more than the \
                     limit of {MAX_ROWS}: split it into several sweeps",
                    views.len(),
                    sweep.rows_per_view()
                ),
            ));
        }
        let render_points = product(&sweep.axes_of(AxisKind::Render));
        let noise_points = product(&sweep.axes_of(AxisKind::Noise));
        let method_points = product(&sweep.axes_of(AxisKind::Method));
        let first = |axes: &Point| {
            axes.iter()
                .all(|(name, value)| sweep.axes[name].first() == Some(value))
        };
        let mut groups = Vec::new();
        let mut position = 0;
        for (vi, view) in views.iter().enumerate() {
            for render_point in &render_points {
                let origin = apply_render_axes(&view.origin, render_point)
                    .map_err(|e| Error::file(&sweep.path, format!("view {}: {e}", view.view)))?;
                let true_eta = true_eta(&origin);
                let mut exposures = Vec::new();
                let stored = matches!(origin, Origin::Stored(_));
                for noise_point in &noise_points {
                    let sensor = (!stored).then(|| sensor(sweep, &view.origin, noise_point));
                    let seeds = if stored { 1 } else { sweep.seeds };
                    for seed in 0..seeds {
                        let mut rows = Vec::new();
                        for method_point in &method_points {
                            for spec in &sweep.methods {
                                let mut axes = render_point.clone();
                                axes.extend(noise_point.clone());
                                axes.extend(method_point.clone());
                                let runner =
                                    row_runner(spec, method_point, &true_eta).map_err(|m| {
                                        Error::file(
                                            &sweep.path,
                                            format!(
                                                "view {}, method {:?}: {m}",
                                                view.view, spec.label
                                            ),
                                        )
                                    })?;
                                let key = row_key(view, &axes, &spec.label, &runner, seed);
                                // An oracle has no normal map to picture.
                                let keep = !matches!(runner, Runner::Oracle(_))
                                    && match sweep.pictures {
                                        super::file::Pictures::First => seed == 0 && first(&axes),
                                        super::file::Pictures::Seed0 => seed == 0,
                                        super::file::Pictures::None => false,
                                    };
                                let pictures = keep.then(|| {
                                    format!(
                                        "pictures/{}/{}/{}/{}",
                                        view.dataset,
                                        view.view,
                                        point_name(&axes),
                                        spec.label
                                    )
                                });
                                rows.push(PlannedRow {
                                    position,
                                    key,
                                    axes,
                                    method: spec.label.clone(),
                                    runner,
                                    seed,
                                    pictures,
                                });
                                position += 1;
                            }
                        }
                        exposures.push(Exposure {
                            sensor: sensor.clone(),
                            seed,
                            rows,
                        });
                    }
                }
                groups.push(Group {
                    view: vi,
                    cache_key: cache_key(&origin),
                    origin,
                    exposures,
                });
            }
        }
        Ok(Plan { views, groups })
    }

    /// Every row in plan order.
    pub fn rows(&self) -> impl Iterator<Item = &PlannedRow> {
        self.groups
            .iter()
            .flat_map(|g| g.exposures.iter().flat_map(|e| e.rows.iter()))
    }
}

/// The views of `sweep.sources[i]`, in a stable order.
fn source_views(sweep: &Sweep, i: usize) -> Result<Vec<PlanView>> {
    let source = &sweep.sources[i];
    let err = |m: String| Error::file(&sweep.path, format!("`views[{i}]`: {m}"));
    let dataset = source.dataset.clone();
    match &source.kind {
        SourceKind::Preset {
            preset,
            size,
            spp,
            views,
            objects,
            svbrdf,
            seed,
        } => {
            let anchor = sweep.path.parent().unwrap_or(Path::new("."));
            let mut d = if Path::new(preset).extension().is_some() {
                Dataset::load(&anchor.join(preset))?
            } else {
                Dataset::preset(preset)?
            };
            d.override_settings(*views, *size, *spp, *seed)?;
            d.desc.dataset.svbrdf |= *svbrdf;
            // Textures are on in the scenes; the `texture` axis turns them off.
            d.desc.dataset.textured = sweep.axes.contains_key(TEXTURE.key);
            if let Some(objects) = objects {
                for o in objects {
                    if !d.desc.objects.iter().any(|p| &p.name == o) {
                        let known: Vec<&str> =
                            d.desc.objects.iter().map(|p| p.name.as_str()).collect();
                        return Err(err(format!(
                            "`objects`: preset {preset:?} has no object {o:?} (it has: {})",
                            known.join(", ")
                        )));
                    }
                }
                d.desc.objects.retain(|o| objects.contains(&o.name));
            }
            let planned = d.plan()?;
            if sweep.axes.contains_key(TEXTURE.key)
                && !planned.iter().any(|v| has_texture(&v.scene))
            {
                return Err(Error::file(
                    &sweep.path,
                    format!(
                        "`axes.texture`: no object of preset {preset:?} in this sweep has an \
                         albedo_texture"
                    ),
                ));
            }
            Ok(planned
                .into_iter()
                .map(|v| PlanView {
                    dataset: dataset.clone(),
                    view: v.folder,
                    object: v.object,
                    origin: Origin::Rendered {
                        scene: Box::new(v.scene),
                        view_index: v.view_index,
                    },
                })
                .collect())
        }
        SourceKind::Scene { path, size, spp } => {
            let mut scene = Scene::load(path)?;
            scene.override_settings(*spp, None, size.map(|s| (s, s)))?;
            if sweep.axes.contains_key(TEXTURE.key) && !has_texture(&scene) {
                return Err(Error::file(
                    &sweep.path,
                    format!(
                        "`axes.texture`: scene {} has no albedo_texture to turn on and off",
                        path.display()
                    ),
                ));
            }
            let name = path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into());
            Ok(vec![PlanView {
                dataset,
                view: name.clone(),
                object: name,
                origin: Origin::Rendered {
                    scene: Box::new(scene),
                    view_index: 0,
                },
            }])
        }
        SourceKind::Analytic { shape, size } => {
            let name = serde_json::to_value(shape)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| "analytic".into());
            Ok(vec![PlanView {
                dataset,
                view: name.clone(),
                object: name,
                origin: Origin::Analytic(AnalyticScene {
                    shape: *shape,
                    size: *size,
                    ..AnalyticScene::default()
                }),
            }])
        }
        SourceKind::Folder { path } => {
            let views = match dataset::classify(path)? {
                Target::View => vec![DatasetView::lone(path)],
                Target::Dataset(views) => views,
            };
            views
                .into_iter()
                .map(|v| {
                    let dir = v.dir.canonicalize().map_err(|e| Error::io(&v.dir, e))?;
                    Ok(PlanView {
                        dataset: dataset.clone(),
                        view: v.folder,
                        object: v.object,
                        origin: Origin::Stored(dir),
                    })
                })
                .collect()
        }
    }
}

fn has_texture(scene: &Scene) -> bool {
    (scene.desc.objects.iter()).any(|o| !o.material.texture_files().is_empty())
}

/// Every combination of the axes' values, the last axis varying fastest; one
/// empty point without axes.
fn product(axes: &[(&str, &[AxisValue])]) -> Vec<Point> {
    let mut points = vec![Point::new()];
    for (name, values) in axes {
        points = points
            .into_iter()
            .flat_map(|p| {
                values.iter().map(move |v| {
                    let mut q = p.clone();
                    q.insert(name.to_string(), v.clone());
                    q
                })
            })
            .collect();
    }
    points
}

/// Folder name of a point: `name=value` joined by `,` (`default` without axes).
pub fn point_name(point: &Point) -> String {
    if point.is_empty() {
        return "default".into();
    }
    point
        .iter()
        .map(|(n, v)| format!("{n}={v}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// The view with the render axes of `point` applied (stored views have
/// none: the sweep file check refuses them).
fn apply_render_axes(origin: &Origin, point: &Point) -> Result<Origin> {
    let render = |name: &str| match axes::axis(name).map(|a| &a.change) {
        Some(Change::Render { scene, analytic }) => (*scene, *analytic),
        _ => unreachable!("{name} is a render axis"),
    };
    match origin {
        Origin::Stored(_) => Ok(origin.clone()),
        Origin::Analytic(a) => {
            let mut change = AnalyticChange {
                scene: a.clone(),
                light: Default::default(),
            };
            for (name, value) in point {
                let set = render(name)
                    .1
                    .expect("the sweep file check: an analytic axis");
                set(&mut change, value);
            }
            change.light.place_analytic(&mut change.scene);
            Ok(Origin::Analytic(change.scene))
        }
        Origin::Rendered { scene, view_index } => {
            let mut change = SceneChange {
                desc: scene.desc.clone(),
                light: Default::default(),
            };
            for (name, value) in point {
                render(name).0(&mut change, value);
            }
            let mut desc = change.desc;
            if change.light.is_set() {
                desc.lights = change.light.lights(scene)?;
            }
            // The cached render is noise-free; rows expose its Stokes.
            desc.sensor = SensorDesc {
                noise: false,
                ..SensorDesc::default()
            };
            Ok(Origin::Rendered {
                scene: Box::new(Scene::new(desc, &scene.source)?),
                view_index: *view_index,
            })
        }
    }
}

/// What a row runs: `spec`'s command as it is (the sweep file check
/// refuses method axes beside commands), an oracle at the view's true η,
/// or its configuration with the true η when the entry asks for it and the
/// method axes of `point` set.
fn row_runner(
    spec: &MethodSpec,
    point: &Point,
    true_eta: &TrueEta,
) -> std::result::Result<Runner, String> {
    match &spec.runner {
        Runner::Command(_) => Ok(spec.runner.clone()),
        Runner::Oracle(oracle) => true_eta.clone().map(|eta| {
            Runner::Oracle(Oracle {
                eta: Some(eta),
                ..*oracle
            })
        }),
        Runner::Registered(config) => {
            method_config(config, spec.eta, point, true_eta).map(Runner::Registered)
        }
    }
}

/// `config` with the true η when `eta` asks for it and the method axes of
/// `point` set.
fn method_config(
    config: &MethodConfig,
    eta: MethodEta,
    point: &Point,
    true_eta: &TrueEta,
) -> std::result::Result<MethodConfig, String> {
    if point.is_empty() && eta == MethodEta::Configured {
        return Ok(config.clone());
    }
    let mut failed = Ok(());
    let config = config.with_shared(|s| {
        if eta == MethodEta::True {
            failed = true_eta.clone().map(|eta| s.eta = eta);
        }
        for (name, value) in point {
            let Some(Change::Method { set, .. }) = axes::axis(name).map(|a| &a.change) else {
                unreachable!("{name} is a method axis")
            };
            if failed.is_ok() {
                failed = set(s, value, true_eta);
            }
        }
    });
    failed?;
    config.map_err(|e| e.to_string())
}

/// The view's true η: its material's (the first object's; all must agree),
/// the analytic η, or the stored `meta.json`'s.
fn true_eta(origin: &Origin) -> std::result::Result<f64, String> {
    match origin {
        Origin::Analytic(a) => Ok(a.eta),
        Origin::Rendered { scene, .. } => {
            let etas: Vec<f64> = scene
                .desc
                .objects
                .iter()
                .map(|o| o.material.eta())
                .collect();
            if etas.windows(2).all(|w| w[0] == w[1]) {
                Ok(etas[0])
            } else {
                Err(format!(
                    "the true η is ambiguous: the objects of {} have different η",
                    scene.source.display()
                ))
            }
        }
        Origin::Stored(dir) => {
            let path = dir.join("meta.json");
            Meta::read(dir)
                .ok()
                .and_then(|m| m.eta)
                .ok_or_else(|| format!("the true η is unknown: {} has no `eta`", path.display()))
        }
    }
}

/// The exposure's sensor: the sweep's `[sensor]` or the view's own (before
/// the render axes, which make the cached render noise-free), with the noise
/// axes of `point`.
fn sensor(sweep: &Sweep, origin: &Origin, point: &Point) -> SensorDesc {
    let mut s = sweep.sensor.clone().unwrap_or_else(|| match origin {
        Origin::Rendered { scene, .. } => scene.desc.sensor.clone(),
        _ => SensorDesc::default(),
    });
    for (name, value) in point {
        let Some(Change::Noise(set)) = axes::axis(name).map(|a| &a.change) else {
            unreachable!("{name} is a noise axis")
        };
        set(&mut s, value);
    }
    s
}

/// Hex SHA-256 of a JSON value's canonical text (keys in order).
pub fn hash_hex(value: &serde_json::Value) -> String {
    let digest = Sha256::digest(value.to_string().as_bytes());
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// The cache name of a noise-free render: a hash of the whole scene (after
/// the axes), its file (relative meshes), its random stream and this
/// software's version; or of the analytic settings.
fn cache_key(origin: &Origin) -> Option<String> {
    let value = match origin {
        Origin::Stored(_) => return None,
        Origin::Analytic(a) => json!({ "version": SOFTWARE_VERSION, "analytic": a }),
        Origin::Rendered { scene, view_index } => json!({
            "version": SOFTWARE_VERSION,
            "scene": scene.desc,
            "source": scene.source.display().to_string(),
            "view_index": view_index,
        }),
    };
    Some(hash_hex(&value)[..16].to_string())
}

/// A row's identity: its view, axis values, method label and configuration
/// and seed.
fn row_key(view: &PlanView, axes: &Point, label: &str, runner: &Runner, seed: u64) -> String {
    let value = json!({
        "dataset": view.dataset,
        "view": view.view,
        "axes": axes,
        "method": label,
        "config": runner.to_value(),
        "seed": seed,
    });
    hash_hex(&value)[..16].to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sfp_renderer::materials::{MapDesc, MaterialDesc};

    fn sweep(text: &str) -> Sweep {
        Sweep::from_toml(text, Path::new("/sweeps/test.toml")).unwrap()
    }

    #[test]
    fn rows_are_every_combination_in_plan_order() {
        let s = sweep(
            r#"
seeds = 2
[[views]]
analytic = "sphere"
size = 16
[axes]
eta = [1.3, 1.6]
noise_read_sigma = [1, 5]
method_eta = [1.5, "true"]
[[methods]]
method = "smith"
[[methods]]
method = "atkinson"
"#,
        );
        let plan = Plan::new(&s).unwrap();
        assert_eq!(plan.groups.len(), 2);
        let rows: Vec<_> = plan.rows().collect();
        assert_eq!(rows.len(), 2 * 2 * 2 * 2 * 2);
        assert!(rows.iter().enumerate().all(|(i, r)| r.position == i));
        let mut keys: Vec<_> = rows.iter().map(|r| &r.key).collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), rows.len());
        // The true η follows the render axis.
        let r = rows
            .iter()
            .find(|r| r.axes["eta"] == AxisValue::Number(1.6) && r.method == "smith")
            .unwrap();
        assert_eq!(r.runner.to_value()["eta"], 1.5);
        let r = rows
            .iter()
            .find(|r| {
                r.axes["eta"] == AxisValue::Number(1.6)
                    && r.axes["method_eta"] == AxisValue::Text("true".into())
            })
            .unwrap();
        assert_eq!(r.runner.to_value()["eta"], 1.6);
        // Pictures: seed 0 at the first value of every axis, each method.
        let pics: Vec<_> = rows.iter().filter_map(|r| r.pictures.as_deref()).collect();
        assert_eq!(
            pics,
            [
                "pictures/analytic/sphere/eta=1.3,method_eta=1.5,noise_read_sigma=1/smith",
                "pictures/analytic/sphere/eta=1.3,method_eta=1.5,noise_read_sigma=1/atkinson"
            ]
        );
        assert_eq!(
            plan.groups[0].exposures[0]
                .sensor
                .as_ref()
                .unwrap()
                .read_noise,
            1.0
        );
    }

    #[test]
    fn light_angles_are_in_the_camera_frame() {
        let s = sweep(
            r#"
[[views]]
preset = "builtin"
objects = ["sphere"]
views = 1
size = 16
spp = 1
[axes]
light_elevation_deg = [90, 30]
light_azimuth_deg = [90]
light = ["two_lights", "environment"]
[[methods]]
method = "smith"
"#,
        );
        let plan = Plan::new(&s).unwrap();
        let lights = |g: &Group| match &g.origin {
            Origin::Rendered { scene, .. } => scene.desc.lights.clone(),
            other => panic!("{other:?}"),
        };
        // Elevation 30°, azimuth 90°: up and towards the camera (+z).
        let g = plan.groups.iter().find(|g| {
            matches!(&lights(g)[..], [l, _]
                if l.direction().is_some_and(|d| (d[2] - 0.5).abs() < 1e-12))
        });
        let direction = lights(g.unwrap())[0].direction().unwrap();
        assert!(direction[0].abs() < 1e-12 && (direction[1] - 0.75f64.sqrt()).abs() < 1e-12);
        assert!(
            plan.groups
                .iter()
                .any(|g| matches!(&lights(g)[..], [l] if l.environment_radiance().is_some()))
        );
        // The render is noise-free; the exposures use the preset's noisy sensor.
        let sensor = plan.groups[0].exposures[0].sensor.as_ref().unwrap();
        assert!(sensor.noise && sensor.full_well == 20000.0, "{sensor:?}");
        // Environment-only renders do not depend on the light angles: one cache entry.
        let keys: std::collections::BTreeSet<_> =
            plan.groups.iter().map(|g| g.cache_key.clone()).collect();
        assert_eq!(keys.len(), 3);
    }

    #[test]
    fn a_preset_seed_draws_other_views() {
        let text = |seed: &str| {
            format!(
                "[[views]]\npreset = \"glossy\"\nobjects = [\"sphere\"]\nviews = 1\nsize = 16\n\
                 spp = 1\n{seed}\n[[methods]]\nmethod = \"smith\"\n"
            )
        };
        let scenes = |t: &str| {
            let plan = Plan::new(&sweep(t)).unwrap();
            plan.groups
                .iter()
                .map(|g| match &g.origin {
                    Origin::Rendered { scene, .. } => {
                        serde_json::to_string(&scene.desc.objects).unwrap()
                    }
                    other => panic!("{other:?}"),
                })
                .collect::<Vec<_>>()
        };
        let preset = scenes(&text(""));
        assert_eq!(preset, scenes(&text("")));
        assert_ne!(preset, scenes(&text("seed = 7")));
        let err = Sweep::from_toml(
            "[[views]]\nanalytic = \"sphere\"\nseed = 7\n[[methods]]\nmethod = \"smith\"\n",
            Path::new("/s.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("seed"), "{err}");
    }

    #[test]
    fn svbrdf_presets_render_their_svbrdf_materials() {
        let text = |svbrdf: &str| {
            format!(
                "[[views]]\npreset = \"builtin\"\nobjects = [\"cup\"]\nviews = 1\nsize = 16\n\
                 spp = 1\n{svbrdf}\n[axes]\nroughness = [0.2]\n[[methods]]\nmethod = \"smith\"\n"
            )
        };
        let materials = |t: &str| {
            let plan = Plan::new(&sweep(t)).unwrap();
            plan.groups
                .iter()
                .map(|g| match &g.origin {
                    Origin::Rendered { scene, .. } => scene.desc.objects[0].material.clone(),
                    other => panic!("{other:?}"),
                })
                .collect::<Vec<_>>()
        };
        for m in materials(&text("svbrdf = true")) {
            let MaterialDesc::Svbrdf(m) = m else {
                panic!("the cup is not SVBRDF: {m:?}")
            };
            // The swept roughness replaces the map.
            assert!(matches!(m.roughness, MapDesc::Constant(r) if r == 0.2));
        }
        for m in materials(&text("")) {
            assert!(matches!(m, MaterialDesc::DiffusePolarized(_)), "{m:?}");
        }
    }
}
