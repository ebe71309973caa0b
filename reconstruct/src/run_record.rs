//! `run.json`, the record of one reconstruction in a result folder
//! (conventions.md §5): written and read by [`RunRecord`] only.

use crate::method_record::MethodRecord;
use crate::methods::MethodConfig;
use serde::{Deserialize, Serialize};
use sfp_core::provenance::{Software, ViewRecord};
use sfp_core::{Error, Result};
use std::path::Path;

/// The record of one reconstruction: the configuration, the time taken and
/// where the input and the software came from, then the method's own
/// record.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunRecord {
    /// The method and every option it ran with.
    pub config: MethodConfig,
    /// Wall time of the reconstruction alone (no I/O), seconds.
    pub seconds: f64,
    /// The view the input came from.
    pub view: ViewRecord,
    pub software: Software,
    /// When, UTC, RFC 3339 to the second.
    pub time: String,
    #[serde(flatten)]
    pub run: MethodRecord,
}

/// The part of a record `sfp eval` checks a view against: read alone, so a
/// record of another version still names its view.
#[derive(Deserialize)]
struct Provenance {
    view: Option<ViewRecord>,
}

impl RunRecord {
    /// The record as `run.json` holds it.
    pub fn to_json(&self) -> Vec<u8> {
        serde_json::to_vec_pretty(self).expect("run record serialises")
    }

    /// Reads `run.json` at `path`.
    pub fn read(path: &Path) -> Result<RunRecord> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        serde_json::from_slice(&bytes)
            .map_err(|e| Error::invalid(format!("{}: invalid run.json: {e}", path.display())))
    }

    /// The view recorded in `run.json` at `path`, when it records one.
    pub fn read_view(path: &Path) -> Result<Option<ViewRecord>> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let p: Provenance = serde_json::from_slice(&bytes)
            .map_err(|e| Error::invalid(format!("{}: invalid run.json: {e}", path.display())))?;
        Ok(p.view)
    }
}
