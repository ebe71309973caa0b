//! The meshes of the presets `a` and `b` shipped with the project
//! (`scenes/meshes/`, sources and licences in `scenes/meshes.md`), compiled
//! in so the presets render from any clone, binary or Python wheel with no
//! download. An `@name` reference finds them when `SFP_MESH_DIR` does not
//! hold `name` (that folder keeps the full-resolution originals).

use std::path::{Path, PathBuf};

/// The folder a shipped file's path names: not a real folder, so a path
/// under it can only be a shipped file, and messages and `meta.json` say
/// where the file came from.
pub const FOLDER: &str = "<shipped>";

/// `(name under scenes/meshes/, content)`.
const FILES: &[(&str, &[u8])] = &[
    (
        "teapot/teapot.obj",
        include_bytes!("../../scenes/meshes/teapot/teapot.obj"),
    ),
    (
        "duck/Duck.glb",
        include_bytes!("../../scenes/meshes/duck/Duck.glb"),
    ),
    (
        "car/car.obj",
        include_bytes!("../../scenes/meshes/car/car.obj"),
    ),
    (
        "camera/camera.glb",
        include_bytes!("../../scenes/meshes/camera/camera.glb"),
    ),
    (
        "cat/cat.obj",
        include_bytes!("../../scenes/meshes/cat/cat.obj"),
    ),
    (
        "human/human_man.obj",
        include_bytes!("../../scenes/meshes/human/human_man.obj"),
    ),
    (
        "goathead/goathead.obj",
        include_bytes!("../../scenes/meshes/goathead/goathead.obj"),
    ),
    (
        "mug/mug.obj",
        include_bytes!("../../scenes/meshes/mug/mug.obj"),
    ),
    (
        "mug/mug.png",
        include_bytes!("../../scenes/meshes/mug/mug.png"),
    ),
];

/// The names of the shipped files (`mug/mug.obj`).
pub fn names() -> impl Iterator<Item = &'static str> {
    FILES.iter().map(|(n, _)| *n)
}

/// The path of the shipped file `name` (`mug/mug.obj`), if there is one.
pub fn path(name: &str) -> Option<PathBuf> {
    FILES
        .iter()
        .any(|(n, _)| *n == name)
        .then(|| Path::new(FOLDER).join(name))
}

/// The content of the shipped file at `path` (as [`path`] gives it).
pub fn bytes(path: &Path) -> Option<&'static [u8]> {
    let name = path.strip_prefix(FOLDER).ok()?;
    FILES
        .iter()
        .find(|(n, _)| Path::new(n) == name)
        .map(|(_, b)| *b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_file_is_found_by_its_name_and_nothing_else_is() {
        for (name, content) in FILES {
            let p = path(name).unwrap();
            assert_eq!(bytes(&p).unwrap().len(), content.len(), "{name}");
        }
        assert!(path("dog/dog0.obj").is_none());
        assert!(bytes(Path::new("scenes/meshes/mug/mug.obj")).is_none());
        assert!(bytes(&Path::new(FOLDER).join("mug")).is_none());
    }
}
