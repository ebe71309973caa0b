//! Under an address-space limit (`prlimit --as`, `ulimit -v`) a
//! reconstruction runs with the threads that fit instead of aborting: each
//! solving thread reserves faer's dense-kernel workspace and a malloc arena
//! whatever the problem, and with 16 threads a 64² view needed more than
//! 1 GB of address space (SIGABRT).

use crate::common::*;
use std::process::Command;

#[test]
fn every_method_runs_in_one_gigabyte_of_address_space() {
    if Command::new("prlimit").arg("--version").output().is_err() {
        eprintln!("skipped: prlimit (util-linux) is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view").display().to_string();
    let o = sfp(&[
        "analytic", "--shape", "sphere", "--size", "64", "--out", &view,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("out").display().to_string();
    let o = Command::new("prlimit")
        .args(["--as=1000000000", env!("CARGO_BIN_EXE_sfp")])
        .args(["reconstruct", &view, "--method", "all", "--out", &out])
        .env("RAYON_NUM_THREADS", "16")
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
}

/// The second case: 16 threads asked for, 4 GB of address space,
/// a 256² view under SMSfP.
#[test]
fn smsfp_at_256_runs_with_sixteen_threads_in_four_gigabytes() {
    if Command::new("prlimit").arg("--version").output().is_err() {
        eprintln!("skipped: prlimit (util-linux) is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view").display().to_string();
    let o = sfp(&[
        "analytic", "--shape", "sphere", "--size", "256", "--out", &view,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("out").display().to_string();
    let o = Command::new("prlimit")
        .args(["--as=4000000000", env!("CARGO_BIN_EXE_sfp")])
        .args(["reconstruct", &view, "--method", "smsfp", "--out", &out])
        .env("RAYON_NUM_THREADS", "16")
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
}
