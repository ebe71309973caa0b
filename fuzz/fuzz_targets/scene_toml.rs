//! Scene files: any text gives a scene or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sfp_renderer::scene::Scene;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = Scene::from_toml(text, Path::new("fuzz/scene.toml"));
    }
});
