//! Shared vocabulary of polar-sfp.
//!
//! Everything here follows `conventions.md` (frames in §1, polarimetry in §2,
//! the diffuse model in §3, metrics in §4, the view layout in §5). The renderer
//! and every reconstruction method speak through these types, so a convention
//! is written down in exactly one place in code.

pub mod analytic;
pub mod capture;
pub mod collection;
pub mod colormap;
pub mod colour;
pub mod error;
pub mod export;
pub mod folder;
pub mod fresnel;
pub mod image;
pub mod inspect;
pub mod instruction_set;
pub mod integral;
pub mod io;
pub mod labelling;
pub mod legend;
pub mod metrics;
pub mod oracle;
pub mod percentile;
pub mod ply;
pub mod prediction;
pub mod provenance;
pub mod regions;
pub mod result_folder;
pub mod stokes;
pub mod text;
pub mod view;

pub use error::{Error, Result};
pub use image::{Image, Mask, NormalMap};

/// Version of this software, recorded in every `meta.json` and `run.json`.
pub const SOFTWARE_VERSION: &str = concat!("polar-sfp ", env!("CARGO_PKG_VERSION"));

/// Commit this software was built from (`git rev-parse HEAD` at build time,
/// "unknown" outside a checkout).
pub const COMMIT: &str = env!("SFP_COMMIT");
