//! A processor without the instructions the build uses (`.cargo/config.toml`)
//! gets a message and exit code 2, not an illegal instruction; one with
//! them runs. `sfp --version` under qemu's user-mode emulation of a
//! SandyBridge (AVX, no AVX2) and of a Haswell (x86-64-v3). Skips with a
//! message where `qemu-x86_64` is not installed (`.ci/run` installs it when
//! it can) or the build needs nothing beyond x86-64.

use std::process::{Command, Output};

/// `sfp --version` on an emulated processor, `None` without qemu.
fn version_on(cpu: &str) -> Option<Output> {
    Command::new("qemu-x86_64")
        .args(["-cpu", cpu, env!("CARGO_BIN_EXE_sfp"), "--version"])
        .output()
        .ok()
}

#[test]
fn only_a_processor_without_avx2_is_refused_and_told_how_to_build() {
    if !cfg!(all(target_arch = "x86_64", target_feature = "avx2")) {
        eprintln!("skipped: this build uses no AVX2");
        return;
    }
    let Some(old) = version_on("SandyBridge") else {
        eprintln!("skipped: qemu-x86_64 is not installed (Debian: qemu-user)");
        return;
    };
    let stderr = String::from_utf8_lossy(&old.stderr);
    assert_eq!(old.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("x86-64-v3") && stderr.contains("target-cpu=native"),
        "{stderr}"
    );
    let new = version_on("Haswell").expect("qemu ran above");
    let stdout = String::from_utf8_lossy(&new.stdout);
    assert!(
        new.status.success() && stdout.starts_with("sfp "),
        "{stdout}"
    );
}
