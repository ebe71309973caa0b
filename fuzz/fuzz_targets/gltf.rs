//! glTF and GLB meshes and their texture images (base colour, metallic-
//! roughness, normal): any bytes give a validated mesh or image, or an error. The
//! first byte picks the container (JSON `.gltf` or binary `.glb`); external
//! buffers resolve inside an empty folder of the fuzzer's own.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sfp_renderer::mesh::Mesh;
use sfp_renderer::texture::{ModelTexture, model_image_from_bytes};
use std::path::PathBuf;
use std::sync::LazyLock;

static FOLDER: LazyLock<PathBuf> = LazyLock::new(|| {
    let dir = std::env::temp_dir().join(format!("sfp-fuzz-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
});

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let name = if kind & 1 == 0 {
        "model.gltf"
    } else {
        "model.glb"
    };
    let path = FOLDER.join(name);
    let _ = Mesh::from_bytes(bytes, &path);
    for which in [
        ModelTexture::BaseColour,
        ModelTexture::MetallicRoughness,
        ModelTexture::Normal,
    ] {
        let _ = model_image_from_bytes(bytes, &path, which);
    }
});
