//! Datasets: a preset TOML (`scenes/datasets/`, format in
//! `scenes/README.md`) → one view folder per object and view, plus
//! `dataset.json` (conventions.md §5).
//!
//! A preset is a scene template (camera, render, lights, sensor, one
//! material) and a list of objects; each object is rendered from
//! `views_per_object` random orientations drawn from the render seed and the
//! view's index, so a dataset is reproducible and a view never changes when
//! other views are added. Generation is resumable: a view folder with
//! `meta.json` is complete (it is written last) and is skipped.

use crate::appearance::{self, Lighting, Vary};
use crate::builtin::BUILTIN_NAMES;
use crate::dataset_index::{DatasetIndex, IndexedView};
use crate::lights::LightDesc;
use crate::materials::MaterialDesc;
use crate::mesh::{Mesh, Placement};
use crate::render::{RenderOptions, render};
use crate::sampler::{Sampler, Stream};
use crate::scene::{
    CameraDesc, MAX_SIDE, ObjectDesc, RenderDesc, Scene, SceneDesc, SensorDesc, check_overrides,
};
use crate::scene_file::{self, MESH_DIR_VAR};
use crate::view_meta::{self, GENERATOR};
use glam::{DQuat, DVec3, EulerRot};
use serde::{Deserialize, Serialize};
use sfp_core::collection::{self, Collection};
use sfp_core::export;
use sfp_core::view::{Meta, SCHEMA_VERSION, View};
use sfp_core::{Error, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The presets shipped in `scenes/datasets/`, by name.
pub const PRESETS: [(&str, &str); 4] = [
    (
        "builtin",
        include_str!("../../scenes/datasets/builtin.toml"),
    ),
    ("a", include_str!("../../scenes/datasets/a.toml")),
    ("b", include_str!("../../scenes/datasets/b.toml")),
    ("glossy", include_str!("../../scenes/datasets/glossy.toml")),
];

/// Views of one object get indices `object << VIEW_BITS | k`: stable when
/// `views_per_object` changes, distinct random streams for every view.
const VIEW_BITS: u32 = 20;

/// A preset file's content. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetDesc {
    pub dataset: DatasetSettings,
    pub camera: CameraDesc,
    #[serde(default)]
    pub render: RenderDesc,
    /// The lights of every view, unless the preset has `[[lighting]]`.
    #[serde(rename = "light", default)]
    pub lights: Vec<LightDesc>,
    /// Sets of lights each view draws one of (`appearance`).
    #[serde(rename = "lighting", default, skip_serializing_if = "Vec::is_empty")]
    pub lightings: Vec<Lighting>,
    /// The material of every object (its `albedo_texture` is set per object).
    pub material: MaterialDesc,
    #[serde(default)]
    pub sensor: SensorDesc,
    #[serde(rename = "object")]
    pub objects: Vec<DatasetObject>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetSettings {
    pub name: String,
    pub views_per_object: usize,
    /// Use each object's `albedo_texture` (objects without one keep the
    /// material's constant albedo).
    #[serde(default)]
    pub textured: bool,
    /// Give each object with an `svbrdf` material that material instead of
    /// the preset's `[material]`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub svbrdf: bool,
    /// Ranges each view draws its material values from (`appearance`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vary: Option<Vary>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetObject {
    /// Folder prefix of its views (`<name>_<k>`).
    pub name: String,
    /// A built-in object (`BUILTIN_NAMES`) ...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub builtin: Option<String>,
    /// ... or a mesh file (relative to the preset, or `@path` in `SFP_MESH_DIR`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// Base orientation (XYZ degrees, as `object.rotate`) before the random rotation.
    #[serde(default)]
    pub rotate: [f64; 3],
    /// Largest angle (degrees) between the object's base `+z` axis and the
    /// view axis; 180 = uniformly random orientation. Open surfaces such as
    /// the `bumps` height field need a small one.
    #[serde(default = "full_turn")]
    pub max_tilt: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo_texture: Option<String>,
    /// The object's material when `[dataset] svbrdf = true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub svbrdf: Option<MaterialDesc>,
}

fn full_turn() -> f64 {
    180.0
}

/// A dataset preset with where it came from (errors, relative paths).
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    pub desc: DatasetDesc,
    pub source: PathBuf,
}

/// One view to render: its folder name, scene and random stream.
#[derive(Clone, Debug)]
pub struct PlannedView {
    /// `<object>_<k>`.
    pub folder: String,
    pub object: String,
    /// Index among the object's views.
    pub k: usize,
    pub view_index: u64,
    pub scene: Scene,
    /// The `[[lighting]]` drawn, if the preset has any.
    pub lighting: Option<String>,
}

/// What [`Dataset::generate`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Generated {
    pub rendered: usize,
    /// Views already on disk with the same settings.
    pub skipped: usize,
    /// Of `rendered`, views that were on disk with other settings.
    pub replaced: usize,
    pub seconds: f64,
}

impl PlannedView {
    /// Whether `dir` holds this view rendered with exactly these settings:
    /// its `meta.json` records the scene and view index it was rendered
    /// from (float settings round-trip exactly: serde_json `float_roundtrip`).
    pub fn is_rendered_in(&self, dir: &Path) -> bool {
        Meta::read(dir).is_ok_and(|meta| view_meta::records(&meta, &self.scene, self.view_index))
    }

    /// Whether the per-angle layout `out` holds this view: its
    /// `normal/NAME.npy`, the last file `export_layout` writes of a view
    /// with ground truth, exists (the settings are not recorded there).
    pub fn is_in_layout(&self, out: &Path) -> bool {
        out.join("normal")
            .join(format!("{}.npy", self.folder))
            .is_file()
    }

    /// The view rendered with its own random streams.
    fn render(&self) -> Result<crate::render::Rendered> {
        render(
            &self.scene,
            &RenderOptions {
                view_index: self.view_index,
            },
        )
    }
}

impl Dataset {
    /// A shipped preset by name (`builtin`, `a`, `b`).
    pub fn preset(name: &str) -> Result<Dataset> {
        let (_, text) = PRESETS.iter().find(|(n, _)| *n == name).ok_or_else(|| {
            let names: Vec<&str> = PRESETS.iter().map(|p| p.0).collect();
            Error::invalid(format!(
                "unknown dataset preset {name:?} (known: {}, or a .toml file)",
                names.join(", ")
            ))
        })?;
        Dataset::from_toml(
            text,
            &Path::new("scenes/datasets").join(format!("{name}.toml")),
        )
    }

    /// Reads and validates a preset file.
    pub fn load(path: &Path) -> Result<Dataset> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::read(path, e))?;
        Dataset::from_toml(&text, path)
    }

    /// Parses preset text as if read from `source`.
    pub fn from_toml(text: &str, source: &Path) -> Result<Dataset> {
        let desc: DatasetDesc = toml::from_str(text)
            .map_err(|e| Error::file(source, e.to_string().trim_end().to_string()))?;
        let dataset = Dataset {
            desc,
            source: source.to_path_buf(),
        };
        dataset.validate()?;
        Ok(dataset)
    }

    /// Command-line overrides: views per object, image size (square), spp, seed.
    pub fn override_settings(
        &mut self,
        views: Option<usize>,
        size: Option<usize>,
        spp: Option<u32>,
        seed: Option<u64>,
    ) -> Result<()> {
        if let Some(v) = views
            && !(1..1 << VIEW_BITS).contains(&v)
        {
            return Err(Error::invalid(format!(
                "--views {v}: must be between 1 and 2^20 - 1"
            )));
        }
        if let Some(s) = size
            && !(1..=MAX_SIDE).contains(&s)
        {
            return Err(Error::invalid(format!(
                "--size {s}: must be between 1 and {MAX_SIDE}"
            )));
        }
        check_overrides(spp, None)?;
        if let Some(v) = views {
            self.desc.dataset.views_per_object = v;
        }
        if let Some(s) = size {
            self.desc.camera.width = s;
            self.desc.camera.height = s;
        }
        if let Some(s) = spp {
            self.desc.render.spp = s;
        }
        if let Some(s) = seed {
            self.desc.render.seed = s;
        }
        self.validate()
    }

    fn err(&self, key: &str, message: impl std::fmt::Display) -> Error {
        Error::file(&self.source, format!("`{key}`: {message}"))
    }

    /// Checks what serde cannot; the scene part is checked by building the
    /// first view of every object as a scene (without loading files).
    fn validate(&self) -> Result<()> {
        let d = &self.desc;
        if d.dataset.views_per_object == 0 || d.dataset.views_per_object >= 1 << VIEW_BITS {
            return Err(self.err("dataset.views_per_object", "must be between 1 and 2^20 - 1"));
        }
        if d.objects.is_empty() {
            return Err(self.err("object", "the dataset has no [[object]]"));
        }
        if d.lights.is_empty() && d.lightings.is_empty() {
            return Err(self.err("light", "the dataset has no [[light]] and no [[lighting]]"));
        }
        if let Some((key, bounds)) = d.dataset.vary.as_ref().and_then(Vary::problem) {
            return Err(self.err(
                &format!("dataset.vary.{key}"),
                format!("must be [low, high] with low ≤ high, {bounds}"),
            ));
        }
        for (i, l) in d.lightings.iter().enumerate() {
            let key = format!("lighting[{i}]");
            if l.name.is_empty() || d.lightings[..i].iter().any(|p| p.name == l.name) {
                return Err(self.err(&key, "needs a `name` no other lighting has"));
            }
            if l.lights.is_empty() {
                return Err(self.err(&key, "has no [[lighting.light]]"));
            }
            let mut desc = self.scene_desc(&d.objects[0], 1.0, d.objects[0].rotate);
            desc.lights = l.lights.clone();
            Scene::new(desc, &self.source).map_err(|e| self.err(&key, e.to_string()))?;
        }
        for (i, o) in d.objects.iter().enumerate() {
            let key = |k: &str| format!("object[{i}].{k}");
            let safe = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
            if o.name.is_empty() || !o.name.chars().all(safe) {
                return Err(self.err(&key("name"), "use letters, digits, `_` and `-` only"));
            }
            if d.objects[..i].iter().any(|p| p.name == o.name) {
                return Err(self.err(&key("name"), format!("{:?} is used twice", o.name)));
            }
            match (&o.builtin, &o.mesh) {
                (Some(b), None) if BUILTIN_NAMES.contains(&b.as_str()) => {}
                (Some(b), None) => {
                    return Err(self.err(
                        &key("builtin"),
                        format!(
                            "unknown built-in object {b:?} (known: {})",
                            BUILTIN_NAMES.join(", ")
                        ),
                    ));
                }
                (None, Some(_)) => {}
                _ => return Err(self.err(&key("builtin"), "give either `builtin` or `mesh`")),
            }
            if !(o.max_tilt > 0.0 && o.max_tilt <= 180.0) {
                return Err(self.err(&key("max_tilt"), "must be in (0, 180] degrees"));
            }
            if !o.rotate.iter().all(|x| x.is_finite()) {
                return Err(self.err(&key("rotate"), "must be finite"));
            }
            Scene::new(self.scene_desc(o, 1.0, o.rotate), &self.source)?;
            if let Some(m) = &o.svbrdf {
                let mut desc = self.scene_desc(o, 1.0, o.rotate);
                desc.objects[0].material = m.clone();
                Scene::new(desc, &self.source)
                    .map_err(|e| self.err(&key("svbrdf"), e.to_string()))?;
            }
        }
        Ok(())
    }

    /// The scene of one view: the template plus the object, scaled by
    /// `scale` (after the unit-box fit for meshes) and rotated by `rotate`.
    fn scene_desc(&self, o: &DatasetObject, scale: f64, rotate: [f64; 3]) -> SceneDesc {
        let d = &self.desc;
        let material = match &o.svbrdf {
            Some(m) if d.dataset.svbrdf => m.clone(),
            _ => {
                let mut m = d.material.clone();
                m.set_albedo_texture(o.albedo_texture.clone().filter(|_| d.dataset.textured));
                m
            }
        };
        SceneDesc {
            camera: d.camera.clone(),
            render: d.render.clone(),
            // With `[[lighting]]` alone, the first stands in until a view draws its own.
            lights: match d.lightings.first() {
                Some(l) if d.lights.is_empty() => l.lights.clone(),
                _ => d.lights.clone(),
            },
            objects: vec![ObjectDesc {
                shape: None,
                mesh: o.mesh.clone(),
                builtin: o.builtin.clone(),
                center: None,
                radius: None,
                normal: None,
                size: None,
                fit_unit_box: o.mesh.is_some(),
                scale,
                rotate,
                translate: [0.0; 3],
                material,
            }],
            sensor: d.sensor.clone(),
        }
    }

    /// Resolves a mesh or texture entry and checks that the file exists,
    /// naming the file and `SFP_MESH_DIR` when it does not.
    fn existing_file(&self, key: &str, file: &str) -> Result<PathBuf> {
        let anchor = Scene {
            desc: self.scene_desc(&self.desc.objects[0], 1.0, [0.0; 3]),
            source: self.source.clone(),
        };
        let path = anchor
            .file_path(file)
            .map_err(|e| self.err(key, e.to_string()))?;
        if scene_file::is_file(&path) {
            return Ok(path);
        }
        if path.is_dir() {
            return Err(Error::file(
                &path,
                format!(
                    "is a folder, not a file (needed by {}: name the file inside it)",
                    self.source.display()
                ),
            ));
        }
        let hint = if file.starts_with('@') {
            format!(" ({file:?} is looked up in {MESH_DIR_VAR}, then among the shipped meshes)")
        } else {
            String::new()
        };
        Err(Error::file(
            &path,
            format!("file not found, needed by {}{hint}", self.source.display()),
        ))
    }

    /// Every view of the dataset, in order. Meshes are loaded once here to
    /// size them to the unit bounding sphere (framed by the preset's camera
    /// in any orientation), so missing files fail before anything renders.
    pub fn plan(&self) -> Result<Vec<PlannedView>> {
        let d = &self.desc;
        let mut views = Vec::new();
        for (i, o) in d.objects.iter().enumerate() {
            let scale = match &o.mesh {
                Some(file) => {
                    let path = self.existing_file(&format!("object[{i}].mesh"), file)?;
                    1.0 / fitted_radius(&Mesh::load(&path)?)
                }
                None => 1.0,
            };
            if let (Some(t), true) = (&o.albedo_texture, d.dataset.textured) {
                self.existing_file(&format!("object[{i}].albedo_texture"), t)?;
            }
            if let (Some(m), true) = (&o.svbrdf, d.dataset.svbrdf) {
                for t in m.texture_files() {
                    self.existing_file(&format!("object[{i}].svbrdf"), t)?;
                }
            }
            for k in 0..d.dataset.views_per_object {
                let view_index = ((i as u64) << VIEW_BITS) | k as u64;
                let q = random_orientation(d.render.seed, view_index, o.max_tilt)
                    * euler_to_quat(o.rotate);
                let mut desc = self.scene_desc(o, scale, quat_to_euler(q));
                let (material, lights, lighting) = appearance::draw(
                    d.render.seed,
                    view_index,
                    d.dataset.vary.as_ref(),
                    &d.lightings,
                    &desc.objects[0].material,
                    &desc.lights,
                );
                desc.objects[0].material = material;
                desc.lights = lights;
                let scene = Scene::new(desc, &self.source)?;
                views.push(PlannedView {
                    folder: format!("{}_{k}", o.name),
                    object: o.name.clone(),
                    k,
                    view_index,
                    scene,
                    lighting,
                });
            }
        }
        Ok(views)
    }

    /// Renders every view of `plan` not yet on disk under `out` with the
    /// same settings ([`PlannedView::is_rendered_in`]), calling
    /// `progress(view, skipped)` after each, then writes `dataset.json`. A
    /// view rendered with other settings (another size, spp, seed …) is
    /// rendered again and replaced whole; a folder without `meta.json` (an
    /// interrupted render) is redone.
    pub fn generate(
        &self,
        plan: &[PlannedView],
        out: &Path,
        progress: &dyn Fn(&PlannedView, bool),
    ) -> Result<Generated> {
        let start = Instant::now();
        let _claim = collection::claim(out, Collection::Dataset)?;
        let (mut rendered, mut skipped, mut replaced) = (0, 0, 0);
        for v in plan {
            let dir = out.join(&v.folder);
            if v.is_rendered_in(&dir) {
                skipped += 1;
                progress(v, true);
                continue;
            }
            if View::is_complete(&dir) {
                replaced += 1;
            } else if dir.exists() {
                std::fs::remove_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
            }
            v.render()?.write(&dir)?;
            rendered += 1;
            progress(v, false);
        }
        self.write_index(plan, out)?;
        Ok(Generated {
            rendered,
            skipped,
            replaced,
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// Renders every view of `plan` straight into the per-angle layout under
    /// `out` (`core::export::export_layout`: `pol000/NAME.png` …, `mask/`,
    /// `normal/`; NAME the view's folder name), for training at scale: no
    /// view folders. A view the layout holds ([`PlannedView::is_in_layout`])
    /// is skipped, so an interrupted run resumes; shards of one plan may write
    /// into one layout at once (their files differ, `layout.json` is the
    /// same). Rendered with other settings, a layout is not detected: give
    /// each setting its own folder.
    pub fn generate_layout(
        &self,
        plan: &[PlannedView],
        out: &Path,
        progress: &dyn Fn(&PlannedView, bool),
    ) -> Result<Generated> {
        let start = Instant::now();
        let (mut rendered, mut skipped) = (0, 0);
        for v in plan {
            if v.is_in_layout(out) {
                skipped += 1;
                progress(v, true);
                continue;
            }
            export::export_layout(&v.render()?.view, &v.folder, out)?;
            rendered += 1;
            progress(v, false);
        }
        Ok(Generated {
            rendered,
            skipped,
            replaced: 0,
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// `dataset.json`: the views and the generator settings (after overrides).
    fn write_index(&self, plan: &[PlannedView], out: &Path) -> Result<()> {
        let views = plan
            .iter()
            .map(|v| IndexedView {
                folder: v.folder.clone(),
                object: Some(v.object.clone()),
                view: Some(v.k),
                view_index: Some(v.view_index),
                rotate: Some(v.scene.desc.objects[0].rotate),
                lighting: v.lighting.clone(),
            })
            .collect();
        let settings = serde_json::to_value(&self.desc)
            .map_err(|e| Error::file(out, format!("cannot record the preset: {e}")))?;
        DatasetIndex {
            schema_version: SCHEMA_VERSION,
            generator: GENERATOR.to_string(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            name: self.desc.dataset.name.clone(),
            preset_file: self.source.display().to_string(),
            settings,
            views,
        }
        .write(out)
    }
}

/// Radius of the bounding sphere about the bounding-box centre after the
/// fit into `[−1, 1]³` (between 1 and √3).
fn fitted_radius(mesh: &Mesh) -> f64 {
    let mut m = mesh.clone();
    m.place(&Placement {
        fit_unit_box: true,
        ..Placement::default()
    });
    let r = m
        .positions
        .iter()
        .map(|p| p.length())
        .fold(0.0f32, f32::max);
    f64::from(r.max(1e-6))
}

/// A random rotation, deterministic in `(seed, view_index)`: the object's
/// `+z` axis goes to a direction uniform over the cap within `max_tilt`
/// degrees of the view axis `+z`, after a uniform spin about `+z`. With
/// `max_tilt = 180` this is the uniform (Haar) distribution of rotations.
pub fn random_orientation(seed: u64, view_index: u64, max_tilt: f64) -> DQuat {
    let mut s = Sampler::new(seed, Stream::Orientation, view_index, 0, 0);
    let spin = std::f64::consts::TAU * s.next_f64();
    let cos_tilt = 1.0 - s.next_f64() * (1.0 - max_tilt.to_radians().cos());
    let azimuth = std::f64::consts::TAU * s.next_f64();
    let axis = DVec3::new(-azimuth.sin(), azimuth.cos(), 0.0);
    DQuat::from_axis_angle(axis, cos_tilt.clamp(-1.0, 1.0).acos()) * DQuat::from_rotation_z(spin)
}

/// The rotation of `object.rotate` (XYZ degrees, x applied first), as in
/// [`Placement::matrix`].
pub fn euler_to_quat(deg: [f64; 3]) -> DQuat {
    let [x, y, z] = deg.map(f64::to_radians);
    DQuat::from_euler(EulerRot::ZYX, z, y, x)
}

/// Inverse of [`euler_to_quat`].
pub fn quat_to_euler(q: DQuat) -> [f64; 3] {
    let (z, y, x) = q.to_euler(EulerRot::ZYX);
    [x, y, z].map(f64::to_degrees)
}
