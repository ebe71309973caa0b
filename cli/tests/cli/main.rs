//! End-to-end checks of the `sfp` binary, one test binary (its tests run
//! side by side; the kill tests' waits overlap the others'), a file per
//! concept: the commands and what a kill leaves behind (`commands`), real
//! captures and their labels (`import`).

mod address_space;
mod colour;
mod commands;
mod common;
mod consistency;
mod dark;
mod eval;
mod exit_codes;
mod import;
mod keys;
mod layout;
mod meshes;
mod messages;
mod outputs;
mod progress;
mod provenance;
mod rgb;
mod sweep_file;
mod unusable;
