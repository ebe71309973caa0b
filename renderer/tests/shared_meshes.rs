//! Every mesh of the shared collection loads (OBJ, GLB, glTF with node
//! transforms, multi-part, non-watertight) and renders with sane ground truth.
//! Needs `SFP_MESH_DIR` (a folder of the meshes listed in its MANIFEST); skips otherwise.

mod common;

use sfp_renderer::render::{RenderOptions, render};
use sfp_renderer::scene::Scene;
use std::path::Path;

const MESHES: [&str; 10] = [
    "teapot/teapot.obj",
    "duck/Duck.glb",
    "beetle_car/beetle.obj",
    "camera/Camera_01_1k.gltf",
    "dog/dog0.obj",
    "human/human_man.obj",
    "goathead/goathead.obj",
    "mug/mug.obj",
    "spot/spot.obj",
    "bunny/bunny.obj",
];

#[test]
#[cfg_attr(not(sfp_mesh_dir), ignore = "needs SFP_MESH_DIR (the preset meshes)")]
fn shared_meshes_render() {
    let Some(dir) = std::env::var_os("SFP_MESH_DIR").filter(|d| Path::new(d).is_dir()) else {
        println!("SKIPPED shared_meshes_render: SFP_MESH_DIR is not set or not a folder");
        return;
    };
    for mesh in MESHES {
        if !Path::new(&dir).join(mesh).is_file() {
            println!("SKIPPED {mesh}: not in SFP_MESH_DIR");
            continue;
        }
        let text = common::EXAMPLE
            .replace(
                "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
                &format!("mesh = \"@{mesh}\"\nfit_unit_box = true"),
            )
            .replace("width = 128", "width = 48")
            .replace("height = 128", "height = 48")
            .replace("spp = 16", "spp = 2")
            .replace("max_depth = 1", "max_depth = 3");
        let scene = Scene::from_toml(&text, Path::new("/tmp/mesh-scene.toml")).unwrap();
        let out =
            render(&scene, &RenderOptions::default()).unwrap_or_else(|e| panic!("{mesh}: {e}"));
        let mask = out.view.input.mask.as_ref().unwrap();
        let gt = out.view.gt.as_ref().unwrap();
        let covered = mask.count();
        assert!(covered > 100, "{mesh}: only {covered} pixels covered");
        for (n, &m) in gt.normals.data().iter().zip(mask.data()) {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if m {
                assert!((len - 1.0).abs() < 1e-4, "{mesh}: normal {n:?}");
            } else {
                assert_eq!(len, 0.0);
            }
        }
        println!(
            "{mesh}: {} triangles, {covered} pixels",
            out.stats.triangles
        );
    }
}
