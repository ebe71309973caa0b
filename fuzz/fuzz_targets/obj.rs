//! OBJ meshes: any bytes give a validated mesh or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sfp_renderer::mesh::Mesh;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = Mesh::from_bytes(data, Path::new("fuzz/mesh.obj"));
});
