//! Records the commit this software is built from (`SFP_COMMIT`), so every
//! `run.json` and sweep can name it; "unknown" outside a git checkout.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=SFP_COMMIT={commit}");
    // Rebuild when HEAD moves: the HEAD file, the branch it names, packed
    // refs (resolved by git, so worktrees work too).
    let mut watched = vec!["HEAD".to_string(), "packed-refs".to_string()];
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watched.push(branch);
    }
    for name in watched {
        if let Some(path) = git(&["rev-parse", "--git-path", &name]) {
            let path = Path::new(&path);
            if path.exists() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
    // Tests on real captures are ignored, with the reason, without them.
    println!("cargo::rustc-check-cfg=cfg(sfp_real_dir)");
    println!("cargo:rerun-if-env-changed=SFP_REAL_DIR");
    if std::env::var_os("SFP_REAL_DIR").is_some() {
        println!("cargo:rustc-cfg=sfp_real_dir");
    }
}
