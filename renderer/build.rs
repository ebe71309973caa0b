//! Tests that need the preset meshes are ignored, with the reason, where
//! `SFP_MESH_DIR` is not set (cfg `sfp_mesh_dir`), so a run shows them as
//! skipped instead of passing without checking anything. The cli's tests
//! use it too (`build` in cli/Cargo.toml).

fn main() {
    println!("cargo::rustc-check-cfg=cfg(sfp_mesh_dir)");
    println!("cargo:rerun-if-env-changed=SFP_MESH_DIR");
    if std::env::var_os("SFP_MESH_DIR").is_some() {
        println!("cargo:rustc-cfg=sfp_mesh_dir");
    }
}
