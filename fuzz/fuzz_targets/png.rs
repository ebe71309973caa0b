//! View PNGs (`input/pol_*.png`, `mask.png`) and capture frames: any bytes
//! give an image or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sfp_core::io::{gray_png_from_bytes, mono_png_from_bytes};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz/pol_000.png");
    if let Ok(gray) = gray_png_from_bytes(data, path) {
        let (w, h) = gray.size();
        assert_eq!(gray.into_u16().data().len(), w * h);
    }
    let _ = mono_png_from_bytes(data, path);
});
