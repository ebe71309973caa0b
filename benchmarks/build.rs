//! Records what a sweep's `provenance.json` reports about the build beyond
//! the commit (`sfp_core::COMMIT`): the versions of the main dependencies
//! (from `Cargo.lock`), as a compile-time environment variable.

use std::path::Path;

/// Dependencies whose versions a sweep records.
const CRATES: [&str; 9] = [
    "faer",
    "nalgebra",
    "rayon",
    "obvhs",
    "glam",
    "exr",
    "image",
    "serde_json",
    "sha2",
];

fn main() {
    let lock_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.lock");
    println!("cargo:rerun-if-changed={}", lock_path.display());
    let lock = std::fs::read_to_string(&lock_path).unwrap_or_default();
    let mut versions = Vec::new();
    let mut name = None;
    for line in lock.lines() {
        if let Some(n) = line.strip_prefix("name = ") {
            name = Some(n.trim_matches('"').to_string());
        } else if let (Some(v), Some(n)) = (line.strip_prefix("version = "), name.take())
            && CRATES.contains(&n.as_str())
        {
            versions.push(format!("{n}={}", v.trim_matches('"')));
        }
    }
    println!("cargo:rustc-env=SFP_DEP_VERSIONS={}", versions.join(","));
}
