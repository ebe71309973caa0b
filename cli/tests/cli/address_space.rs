//! Under an address-space limit (`prlimit --as`, `ulimit -v`) a
//! reconstruction runs with the threads that fit instead of aborting: each
//! solving thread reserves faer's dense-kernel workspace and a malloc arena
//! whatever the problem, and with 16 threads a 64² view needed more than
//! 1 GB of address space (SIGABRT).

use crate::common::*;
use std::process::Command;

/// `sfp reconstruct` of a `size`² sphere with `method`, 16 threads asked
/// for, under `prlimit --as=BYTES`; skipped without prlimit.
fn reconstruct_limited(size: &str, method: &str, bytes: &str) {
    if Command::new("prlimit").arg("--version").output().is_err() {
        eprintln!("skipped: prlimit (util-linux) is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view").display().to_string();
    sfp_ok(&[
        "analytic", "--shape", "sphere", "--size", size, "--out", &view,
    ]);
    let out = dir.path().join("out").display().to_string();
    let o = Command::new("prlimit")
        .args([&format!("--as={bytes}"), env!("CARGO_BIN_EXE_sfp")])
        .args(["reconstruct", &view, "--method", method, "--out", &out])
        .env("RAYON_NUM_THREADS", "16")
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
}

#[test]
fn every_method_runs_in_one_gigabyte_of_address_space() {
    reconstruct_limited("64", "all", "1000000000");
}

/// The second case: 16 threads asked for, 4 GB of address space,
/// a 256² view under SMSfP.
#[test]
fn smsfp_at_256_runs_with_sixteen_threads_in_four_gigabytes() {
    reconstruct_limited("256", "smsfp", "4000000000");
}
