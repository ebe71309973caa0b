//! What every end-to-end check of the `sfp` binary needs: running it and
//! reading what it wrote or printed.

use std::path::Path;
use std::process::{Command, Output};

pub fn sfp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sfp"))
        .args(args)
        .output()
        .expect("sfp runs")
}

/// A JSON file the command wrote.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// Runs `sfp` and checks that it succeeded, showing its stderr when not.
pub fn sfp_ok(args: &[&str]) -> Output {
    let o = sfp(args);
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn assert_clean_failure(o: &Output, needle: &str) {
    assert!(!o.status.success());
    let e = stderr(o);
    assert!(!e.contains("panicked"), "{e}");
    assert!(e.contains(needle), "expected {needle:?} in: {e}");
}

/// A 16² analytic view written to `dir/view`, and its path as text.
pub fn small_view(dir: &Path) -> String {
    let view = dir.join("view").display().to_string();
    sfp_ok(&["analytic", "--size", "16", "--out", &view]);
    view
}
