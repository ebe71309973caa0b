//! View EXRs (`gt/normals.exr`, depth, Stokes): any bytes give the named
//! channels or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sfp_core::io::exr_from_bytes;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz/normals.exr");
    if let Ok(channels) = exr_from_bytes(data, path, &["R", "G", "B"]) {
        let size = channels[0].size();
        assert!(channels.iter().all(|c| c.size() == size));
    }
    let _ = exr_from_bytes(data, path, &["Z"]);
});
