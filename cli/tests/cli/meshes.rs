//! The presets' meshes: shipped ones render with no `SFP_MESH_DIR`, and
//! `scenes/fetch-meshes.sh` fetches the originals, offline from a local copy
//! (`SFP_MESH_DIR`) into a new folder, every file checked by its hash.

use crate::common::{read_json, stderr};
use std::path::Path;
use std::process::Command;

/// A fresh clone has no `SFP_MESH_DIR`: presets `a` and `b` render from the
/// shipped meshes, and a folder without them changes nothing.
#[test]
fn presets_a_and_b_render_from_the_shipped_meshes() {
    let dir = tempfile::tempdir().unwrap();
    for (preset, env) in [("a", None), ("b", Some(dir.path()))] {
        let out = dir.path().join(preset);
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_sfp"));
        cmd.args(["dataset", preset, "--size", "24", "--spp", "1", "--out"])
            .arg(&out);
        match env {
            Some(empty) => cmd.env("SFP_MESH_DIR", empty),
            None => cmd.env_remove("SFP_MESH_DIR"),
        };
        let o = cmd.output().unwrap();
        assert!(o.status.success(), "{preset}: {}", stderr(&o));
        let index = read_json(&out.join("dataset.json"));
        let views = index["views"].as_array().unwrap();
        assert_eq!(views.len(), 4, "{preset}: {index}");
        for v in views {
            let folder = out.join(v["folder"].as_str().unwrap());
            let meta = read_json(&folder.join("meta.json"));
            let file = meta["mesh_files"][0]["file"].as_str().unwrap();
            assert!(file.starts_with("<shipped>/"), "{preset}: {file}");
        }
    }
}

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/fetch-meshes.sh");

fn fetch(from: &Path, dest: &Path) -> std::process::Output {
    Command::new("bash")
        .arg(SCRIPT)
        .arg("--from")
        .arg(from)
        .arg(dest)
        .output()
        .unwrap()
}

#[test]
#[cfg_attr(not(sfp_mesh_dir), ignore = "needs SFP_MESH_DIR (the preset meshes)")]
fn the_preset_meshes_are_fetched_and_checked() {
    let Some(meshes) = std::env::var_os("SFP_MESH_DIR") else {
        eprintln!("SKIPPED the_preset_meshes_are_fetched_and_checked: SFP_MESH_DIR is not set");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let dest = dir.path().join("meshes");
    let o = fetch(Path::new(&meshes), &dest);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for f in [
        "teapot/teapot.obj",
        "duck/Duck.glb",
        "camera/textures/Camera_01_body_diff_1k.jpg",
        "mug/mug.png",
    ] {
        assert!(dest.join(f).is_file(), "{f}");
    }
    // A mirror with another version of a file: refused, nothing written.
    let mirror = dir.path().join("mirror");
    std::fs::create_dir_all(mirror.join("teapot")).unwrap();
    std::fs::write(mirror.join("teapot/teapot.obj"), "v 0 0 0\n").unwrap();
    let fresh = dir.path().join("fresh");
    let o = fetch(&mirror, &fresh);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("wrong    teapot/teapot.obj"));
    assert!(!fresh.join("teapot/teapot.obj").exists());
}
