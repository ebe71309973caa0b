//! Scene files: TOML → [`Scene`] (format documented in `scenes/README.md`).
//!
//! The scene as a whole (camera, render settings, objects and their
//! placement, sensor) is read here; each `[[light]]` and each object's
//! `material` is read, checked and built by its kind (`lights/`,
//! `materials/`). Unknown keys, wrong types and impossible values are errors
//! that name the file and the key. Mesh paths are relative to the scene
//! file, or to the `SFP_MESH_DIR` directory when written `@name.obj`.

use crate::builtin::BUILTIN_NAMES;
use crate::lights::LightDesc;
use crate::materials::MaterialDesc;
use crate::scene_file::{self, Table};
use serde::{Deserialize, Serialize};
use sfp_core::{Error, Result};
use std::path::{Path, PathBuf};

/// A parsed and validated scene, with where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub desc: SceneDesc,
    /// The scene file (for error messages and relative mesh paths).
    pub source: PathBuf,
}

/// The scene file's content. Field names are the file's keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    pub camera: CameraDesc,
    #[serde(default)]
    pub render: RenderDesc,
    #[serde(default, rename = "light")]
    pub lights: Vec<LightDesc>,
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectDesc>,
    #[serde(default)]
    pub sensor: SensorDesc,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CameraKind {
    Orthographic,
    Perspective,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    #[serde(rename = "type")]
    pub kind: CameraKind,
    pub width: usize,
    pub height: usize,
    /// Orthographic: world width spanned by the image.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extent: Option<f64>,
    /// Perspective: horizontal field of view in degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov: Option<f64>,
    pub position: [f64; 3],
    pub look_at: [f64; 3],
    #[serde(default = "default_up")]
    pub up: [f64; 3],
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderDesc {
    /// Samples per pixel.
    pub spp: u32,
    /// Surface interactions per path: 1 = direct lighting only.
    pub max_depth: u32,
    pub seed: u64,
    /// Jitter samples over the pixel; `false` puts every sample at the centre.
    pub jitter: bool,
    /// First depth at which Russian roulette may end a path.
    pub rr_depth: u32,
    /// Render R, G, B (a colour view, conventions.md §5) instead of grey.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub colour: bool,
}

impl Default for RenderDesc {
    fn default() -> Self {
        RenderDesc {
            spp: 16,
            max_depth: 4,
            seed: 0,
            jitter: true,
            rr_depth: 3,
            colour: false,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    Sphere,
    Plane,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeKind>,
    /// Mesh file, relative to the scene file, or `@name` in `SFP_MESH_DIR`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// Procedural built-in object (`crate::builtin::BUILTIN_NAMES`), placed like a mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub builtin: Option<String>,
    /// Sphere centre or plane centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Plane normal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// Plane side length (absent: infinite).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<f64>,
    /// Mesh placement: fit into `[−1, 1]³`, scale, rotate (XYZ degrees), translate.
    #[serde(default)]
    pub fit_unit_box: bool,
    #[serde(default = "unit_scale")]
    pub scale: f64,
    #[serde(default)]
    pub rotate: [f64; 3],
    #[serde(default)]
    pub translate: [f64; 3],
    pub material: MaterialDesc,
}

fn unit_scale() -> f64 {
    1.0
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorDesc {
    /// Quantization bits (8–16).
    pub bits: u8,
    /// Shot and read noise on/off (quantization and clipping always apply).
    pub noise: bool,
    /// Exposure: this quantile (0–1) of `s0` inside the mask ...
    pub exposure_percentile: f64,
    /// ... is mapped to this fraction of full scale.
    pub exposure_level: f64,
    /// Electrons at full scale (sets the shot-noise level).
    pub full_well: f64,
    /// Gaussian read noise, standard deviation in electrons.
    pub read_noise: f64,
    /// Also write `input/raw.png`, the 2×2 division-of-focal-plane mosaic
    /// (of a colour render: IMX250MYR's, each cell under one filter, RGGB).
    pub mosaic: bool,
}

impl SensorDesc {
    /// The first out-of-range setting, as (key, what it must be): a scene's
    /// `[sensor]` and a sweep's are checked alike.
    pub fn check(&self) -> std::result::Result<(), (&'static str, &'static str)> {
        if !(8..=16).contains(&self.bits) {
            return Err(("bits", "must be between 8 and 16"));
        }
        if !(self.exposure_percentile > 0.0 && self.exposure_percentile <= 1.0) {
            return Err(("exposure_percentile", "must be in (0, 1]"));
        }
        if !(self.exposure_level > 0.0 && self.exposure_level.is_finite()) {
            return Err(("exposure_level", "must be positive"));
        }
        if !(self.full_well > 0.0 && self.full_well.is_finite()) {
            return Err(("full_well", "must be positive"));
        }
        if !(self.read_noise >= 0.0 && self.read_noise.is_finite()) {
            return Err(("read_noise", "must be finite and ≥ 0"));
        }
        Ok(())
    }
}

impl Default for SensorDesc {
    fn default() -> Self {
        SensorDesc {
            bits: 16,
            noise: true,
            exposure_percentile: 0.99,
            exposure_level: 0.8,
            full_well: 20000.0,
            read_noise: 2.0,
            mosaic: false,
        }
    }
}

impl Scene {
    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::read(path, e))?;
        Scene::from_toml(&text, path)
    }

    /// Parses scene text as if read from `source` (which names errors and
    /// anchors relative mesh paths).
    pub fn from_toml(text: &str, source: &Path) -> Result<Scene> {
        let desc: SceneDesc = toml::from_str(text)
            .map_err(|e| Error::file(source, e.to_string().trim_end().to_string()))?;
        Scene::new(desc, source)
    }

    /// A scene built in code (datasets), validated like a file's content.
    pub fn new(desc: SceneDesc, source: &Path) -> Result<Scene> {
        let scene = Scene {
            desc,
            source: source.to_path_buf(),
        };
        scene.validate()?;
        Ok(scene)
    }

    /// Applies command-line overrides (`--spp`, `--seed`, `--size WxH`) and
    /// validates again.
    pub fn override_settings(
        &mut self,
        spp: Option<u32>,
        seed: Option<u64>,
        size: Option<(usize, usize)>,
    ) -> Result<()> {
        check_overrides(spp, size)?;
        if let Some(spp) = spp {
            self.desc.render.spp = spp;
        }
        if let Some(seed) = seed {
            self.desc.render.seed = seed;
        }
        if let Some((w, h)) = size {
            self.desc.camera.width = w;
            self.desc.camera.height = h;
        }
        self.validate()
    }

    fn err(&self, key: &str, message: impl std::fmt::Display) -> Error {
        Error::file(&self.source, format!("`{key}`: {message}"))
    }

    /// Resolves a file entry (`mesh`, environment `map`, texture): relative
    /// to the scene file, or `@name` in `SFP_MESH_DIR`. Existence is checked
    /// on load.
    pub fn file_path(&self, file: &str) -> Result<PathBuf> {
        scene_file::resolve(&self.source, file)
    }

    /// Checks values serde cannot: ranges, required combinations.
    fn validate(&self) -> Result<()> {
        let d = &self.desc;
        let c = &d.camera;
        if !side_in_range(c.width) || !side_in_range(c.height) {
            return Err(self.err("camera.width/height", "must be between 1 and 16384"));
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if !finite(&c.position) || !finite(&c.look_at) || !finite(&c.up) {
            return Err(self.err("camera", "position, look_at and up must be finite"));
        }
        match c.kind {
            CameraKind::Orthographic => match c.extent {
                Some(e) if e > 0.0 && e.is_finite() => {}
                Some(_) => return Err(self.err("camera.extent", "must be positive")),
                None => {
                    return Err(self.err("camera.extent", "required for an orthographic camera"));
                }
            },
            CameraKind::Perspective => match c.fov {
                Some(f) if f > 0.0 && f < 180.0 => {}
                Some(_) => return Err(self.err("camera.fov", "must be in (0, 180) degrees")),
                None => return Err(self.err("camera.fov", "required for a perspective camera")),
            },
        }
        if d.render.spp == 0 {
            return Err(self.err("render.spp", "must be at least 1"));
        }
        if d.render.max_depth == 0 {
            return Err(self.err("render.max_depth", "must be at least 1"));
        }
        for (i, l) in d.lights.iter().enumerate() {
            l.validate(&Table::new(&self.source, format!("light[{i}]")))?;
        }
        let environments = d
            .lights
            .iter()
            .filter(|l| l.environment_radiance().is_some())
            .count();
        if environments > 1 {
            return Err(self.err("light", "at most one environment light"));
        }
        if d.lights.is_empty() {
            return Err(self.err("light", "the scene has no [[light]]"));
        }
        if d.objects.is_empty() {
            return Err(self.err("object", "the scene has no [[object]]"));
        }
        for (i, o) in d.objects.iter().enumerate() {
            self.validate_object(i, o)?;
        }
        d.sensor
            .check()
            .map_err(|(key, message)| self.err(&format!("sensor.{key}"), message))
    }

    fn validate_object(&self, i: usize, o: &ObjectDesc) -> Result<()> {
        let key = |k: &str| format!("object[{i}].{k}");
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let kinds = [o.shape.is_some(), o.mesh.is_some(), o.builtin.is_some()];
        if kinds.iter().filter(|&&k| k).count() != 1 {
            return Err(self.err(
                &key("shape"),
                "give exactly one of `shape`, `mesh` or `builtin`",
            ));
        }
        if let Some(name) = &o.builtin
            && !BUILTIN_NAMES.contains(&name.as_str())
        {
            return Err(self.err(
                &key("builtin"),
                format!(
                    "unknown built-in object {name:?} (known: {})",
                    BUILTIN_NAMES.join(", ")
                ),
            ));
        }
        match o.shape {
            Some(ShapeKind::Sphere) => {
                if !matches!(o.radius, Some(r) if r > 0.0 && r.is_finite()) {
                    return Err(self.err(&key("radius"), "a sphere needs a positive `radius`"));
                }
                if o.normal.is_some() || o.size.is_some() {
                    return Err(self.err(&key("normal"), "`normal`/`size` belong to planes"));
                }
            }
            Some(ShapeKind::Plane) => {
                match o.normal {
                    Some(n) if finite(&n) && n.iter().any(|&x| x != 0.0) => {}
                    _ => return Err(self.err(&key("normal"), "a plane needs a non-zero `normal`")),
                }
                if o.radius.is_some() {
                    return Err(self.err(&key("radius"), "`radius` belongs to spheres"));
                }
                if let Some(s) = o.size
                    && !(s > 0.0 && s.is_finite())
                {
                    return Err(self.err(&key("size"), "must be positive"));
                }
            }
            None => {
                if o.center.is_some()
                    || o.radius.is_some()
                    || o.normal.is_some()
                    || o.size.is_some()
                {
                    return Err(self.err(
                        &key("center"),
                        "meshes and built-ins are placed with `translate`, `rotate`, `scale`, `fit_unit_box`",
                    ));
                }
            }
        }
        if let Some(c) = o.center
            && !finite(&c)
        {
            return Err(self.err(&key("center"), "must be finite"));
        }
        if !(o.scale > 0.0 && o.scale.is_finite() && finite(&o.rotate) && finite(&o.translate)) {
            return Err(self.err(
                &key("scale"),
                "scale must be positive; rotate/translate finite",
            ));
        }
        o.material
            .validate(&Table::new(&self.source, format!("object[{i}].material")))
    }
}

/// Largest image side the renderer accepts.
pub const MAX_SIDE: usize = 1 << 14;

fn side_in_range(side: usize) -> bool {
    (1..=MAX_SIDE).contains(&side)
}

/// Checks values given on the command line before they replace the scene
/// file's, so an error names the option the user typed, not a key of a file
/// they did not edit.
pub fn check_overrides(spp: Option<u32>, size: Option<(usize, usize)>) -> Result<()> {
    if spp == Some(0) {
        return Err(Error::invalid("--spp 0: must be at least 1"));
    }
    if let Some((w, h)) = size
        && !(side_in_range(w) && side_in_range(h))
    {
        return Err(Error::invalid(format!(
            "--size {w}x{h}: width and height must be between 1 and {MAX_SIDE}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE: &str = include_str!("../../scenes/examples/sphere.toml");

    fn parse(text: &str) -> Result<Scene> {
        Scene::from_toml(text, Path::new("/scenes/test.toml"))
    }

    #[test]
    fn documented_example_parses() {
        let s = parse(EXAMPLE).unwrap();
        assert_eq!(s.desc.camera.width, 128);
        assert_eq!(s.desc.render.max_depth, 1);
        assert!(!s.desc.sensor.noise);
        assert_eq!(s.desc.objects.len(), 1);
    }

    #[test]
    fn errors_name_file_and_key() {
        let cases = [
            (
                EXAMPLE.replace("radius = 1.0", "radius = 1.0\nradiuss = 2.0"),
                "radiuss",
            ),
            (
                EXAMPLE.replace("spp = 16", "spp = 16\nsamples = 3"),
                "samples",
            ),
            (EXAMPLE.replace("diffuse_polarized", "velvet"), "velvet"),
            (
                EXAMPLE.replace("eta = 1.5 }", "eta = 1.5, gloss = 1 }"),
                "gloss",
            ),
            (
                EXAMPLE.replace("irradiance = 3.0", "irradiance = 3.0\nsize = 1"),
                "size",
            ),
            (EXAMPLE.replace("radius = 1.0", "radius = -1.0"), "radius"),
            (EXAMPLE.replace("extent = 2.2", ""), "extent"),
            (EXAMPLE.replace("spp = 16", "spp = \"many\""), "spp"),
            (EXAMPLE.replace("bits = 16", "bits = 4"), "bits"),
            (EXAMPLE.replace("eta = 1.5", "eta = 0.5"), "eta"),
        ];
        for (text, key) in cases {
            let err = parse(&text).expect_err(key).to_string();
            assert!(
                err.contains("test.toml") && err.contains(key),
                "{key}: {err}"
            );
        }
    }

    #[test]
    fn builtin_objects_parse_with_mesh_placement() {
        let builtin = |extra: &str| {
            EXAMPLE.replace(
                "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
                &format!("builtin = \"cup\"\nrotate = [10.0, 0.0, 0.0]{extra}"),
            )
        };
        let s = parse(&builtin("")).unwrap();
        assert_eq!(s.desc.objects[0].builtin.as_deref(), Some("cup"));
        assert_eq!(s.desc.objects[0].rotate, [10.0, 0.0, 0.0]);
        for (extra, key) in [
            ("\nradius = 1.0", "`translate`"),
            ("\nmesh = \"a.obj\"", "`mesh`"),
            ("\nshape = \"plane\"", "`shape`"),
        ] {
            let err = parse(&builtin(extra)).expect_err(key).to_string();
            assert!(
                err.contains("test.toml") && err.contains(key),
                "{key}: {err}"
            );
        }
        let err = parse(&builtin("").replace("\"cup\"", "\"vase\""))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("object[0].builtin") && err.contains("snowman"),
            "{err}"
        );
    }

    #[test]
    fn mesh_paths_resolve_relative_to_scene() {
        let s = parse(EXAMPLE).unwrap();
        assert_eq!(
            s.file_path("m/a.obj").unwrap(),
            PathBuf::from("/scenes/m/a.obj")
        );
    }
}
