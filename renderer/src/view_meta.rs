//! A rendered view's record in `meta.json` (conventions.md §5): the
//! renderer's writer (`record`) and reader ([`Scene::from_meta`]) of the
//! keys it adds, side by side so they agree. The record holds the complete
//! scene (after any overrides) and how it was resolved, so the view can be
//! re-rendered bit-identically.

use crate::lights::Light;
use crate::scene::{Scene, SceneDesc};
use crate::world::World;
use serde_json::{Value, json};
use sfp_core::view::Meta;
use sfp_core::{Error, Result};
use std::path::Path;

/// Name written into `meta.json`'s `generator`.
pub const GENERATOR: &str = "sfp-renderer";

impl Scene {
    /// The scene a rendered view's `meta.json` records (`scene`,
    /// `scene_file`), to re-render it bit-identically, and its view index.
    pub fn from_meta(meta: &Meta, meta_path: &Path) -> Result<(Scene, u64)> {
        let missing = |key: &str| {
            Error::file(
                meta_path,
                format!("`{key}` missing: not written by {GENERATOR}"),
            )
        };
        let desc = meta.extra.get("scene").ok_or_else(|| missing("scene"))?;
        let desc: SceneDesc = serde_json::from_value(desc.clone())
            .map_err(|e| Error::file(meta_path, format!("`scene`: {e}")))?;
        let source = meta
            .extra
            .get("scene_file")
            .and_then(|v| v.as_str())
            .ok_or_else(|| missing("scene_file"))?;
        let view = meta
            .extra
            .get("view_index")
            .and_then(|v| v.as_u64())
            .unwrap_or(0);
        Ok((Scene::new(desc, Path::new(source))?, view))
    }
}

/// Whether `meta` records `scene` rendered as view `view_index`, as
/// [`record`] writes them (float settings round-trip exactly: serde_json
/// `float_roundtrip`), so a dataset skips a view already on disk.
pub(crate) fn records(meta: &Meta, scene: &Scene, view_index: u64) -> bool {
    serde_json::to_value(&scene.desc).is_ok_and(|desc| meta.extra.get("scene") == Some(&desc))
        && meta.extra.get("view_index") == Some(&json!(view_index))
}

/// `meta.json`: the complete scene (after any overrides) and how it was
/// resolved, so the view can be re-rendered bit-identically.
pub(crate) fn record(scene: &Scene, world: &World, view_index: u64, exposure: f64) -> Result<Meta> {
    let d = &scene.desc;
    let mut m = Meta::new(GENERATOR);
    // (albedo if constant over the surface, η)
    let materials: Vec<(Option<f64>, f64)> = d
        .objects
        .iter()
        .map(|o| (o.material.constant_albedo(), o.material.eta()))
        .collect();
    if materials.windows(2).all(|p| p[0].1 == p[1].1) {
        m.eta = Some(materials[0].1);
    }
    if materials.windows(2).all(|p| p[0] == p[1]) {
        m.albedo = materials[0].0;
    }
    let brightest = world
        .lights
        .iter()
        .filter_map(Light::directional_irradiance)
        .map(|(e, dir)| (f64::from(e), dir))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((e, dir)) = brightest {
        let c = world.camera.to_camera(dir);
        m.light = Some([c.x, c.y, c.z].map(|v| f64::from(v) * e));
    }
    let meshes: Vec<Value> = d
        .objects
        .iter()
        .filter_map(|o| o.mesh.as_ref())
        .map(|mesh| Ok(json!({"mesh": mesh, "file": scene.file_path(mesh)?.display().to_string()})))
        .collect::<Result<_>>()?;
    let scene_json = serde_json::to_value(d)
        .map_err(|e| Error::file(&scene.source, format!("cannot record the scene: {e}")))?;
    m.extra.insert("scene".into(), scene_json);
    m.extra.insert(
        "scene_file".into(),
        json!(scene.source.display().to_string()),
    );
    m.extra.insert("mesh_files".into(), Value::Array(meshes));
    m.extra.insert("view_index".into(), json!(view_index));
    m.extra.insert("exposure_scale".into(), json!(exposure));
    m.extra.insert(
        "conventions".into(),
        json!(
            "Stokes in the camera frame of conventions.md §1; max_depth counts surface interactions"
        ),
    );
    Ok(m)
}
