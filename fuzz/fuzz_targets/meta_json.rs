//! `meta.json`: any bytes give a record or an error, and so does the scene a
//! rendered view's record reproduces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sfp_core::view::Meta;
use sfp_renderer::scene::Scene;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz/meta.json");
    if let Ok(meta) = Meta::from_json(data, path) {
        let _ = Scene::from_meta(&meta, path);
    }
});
