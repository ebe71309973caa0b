//! Bad input gives an error that names the file (and key), never a panic.

mod common;

use common::EXAMPLE;
use sfp_renderer::render::{RenderOptions, render};
use sfp_renderer::scene::Scene;
use std::path::Path;

fn sphere_to_mesh(mesh: &str) -> String {
    EXAMPLE.replace(
        "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        &format!("mesh = \"{mesh}\""),
    )
}

/// Parses and renders; returns the error text.
fn failure(text: &str, dir: &Path) -> String {
    let scene_path = dir.join("scene.toml");
    match Scene::from_toml(text, &scene_path) {
        Err(e) => e.to_string(),
        Ok(scene) => match render(&scene, &RenderOptions::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("rendered without error:\n{text}"),
        },
    }
}

#[test]
fn bad_scenes_and_meshes_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("nan.obj"), "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(d.join("broken.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    std::fs::write(d.join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    std::fs::write(d.join("broken.glb"), b"glTF\x02\x00\x00\x00garbage").unwrap();
    let cases: Vec<(String, &str)> = vec![
        (sphere_to_mesh("missing.obj"), "missing.obj"),
        (sphere_to_mesh("nan.obj"), "nan.obj"),
        (sphere_to_mesh("broken.obj"), "broken.obj"),
        (sphere_to_mesh("flat.obj"), "flat.obj"),
        (sphere_to_mesh("broken.glb"), "broken.glb"),
        (
            EXAMPLE.replace("diffuse_polarized", "lambertian"),
            "lambertian",
        ),
        (
            EXAMPLE.replace("radius = 1.0", "radius = 1.0\ncolour = 3"),
            "colour",
        ),
        (EXAMPLE.replace("[sensor]", "[sensor]\ngain = 2"), "gain"),
        // The camera looks away from everything.
        (
            EXAMPLE.replace("look_at = [0.0, 0.0, 0.0]", "look_at = [0.0, 0.0, 9.0]"),
            "visible",
        ),
        (
            EXAMPLE.replace("up = [0.0, 1.0, 0.0]", "up = [0.0, 0.0, 1.0]"),
            "camera",
        ),
        (
            EXAMPLE.replace("direction = [0.4, 0.3, 1.0]", "direction = [0.0, 0.0, 0.0]"),
            "direction",
        ),
    ];
    for (text, key) in cases {
        let err = failure(&text, d);
        println!("{err}");
        assert!(err.contains(key), "expected `{key}` in: {err}");
        assert!(
            err.contains("scene.toml") || err.contains(".obj") || err.contains(".glb"),
            "{err}"
        );
    }
}

#[test]
fn mesh_dir_references_need_the_variable_or_the_folder() {
    // `@name` resolves in SFP_MESH_DIR; this process never sets it, so the
    // error must say which variable is missing.
    if std::env::var_os("SFP_MESH_DIR").is_some() {
        println!("SFP_MESH_DIR is set in this environment; checking a missing file instead");
        let err = failure(&sphere_to_mesh("@no-such-mesh.obj"), Path::new("/tmp"));
        assert!(err.contains("no-such-mesh.obj"), "{err}");
        return;
    }
    let err = failure(&sphere_to_mesh("@bunny.obj"), Path::new("/tmp"));
    assert!(err.contains("SFP_MESH_DIR"), "{err}");
}

#[test]
fn bad_surroundings_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let with = |table: &str| {
        format!("{EXAMPLE}\n[[light]]\ntype = \"environment\"\nradiance = 1.0\n{table}\n")
    };
    let both = failure(
        &with("map = \"sky.exr\"\nsurroundings = { kind = \"sky\" }"),
        dir.path(),
    );
    assert!(both.contains("either `map` or `surroundings`"), "{both}");
    let high = failure(
        &with("surroundings = { kind = \"sky\", sun_elevation = 95.0 }"),
        dir.path(),
    );
    assert!(
        high.contains("sun_elevation") && high.contains("[0, 90]"),
        "{high}"
    );
    let kind = failure(&with("surroundings = { kind = \"cave\" }"), dir.path());
    assert!(kind.contains("cave") && kind.contains("room"), "{kind}");
}
