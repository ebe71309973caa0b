//! `run.json`, the record of one reconstruction in a result folder
//! (conventions.md §5): written and read by [`RunRecord`] only.

use crate::input::Unusable;
use crate::method_record::MethodRecord;
use crate::methods::MethodConfig;
use crate::specular::beyond_diffuse::BeyondDiffuse;
use serde::{Deserialize, Serialize};
use sfp_core::Result;
use sfp_core::provenance::{Software, ViewRecord};
use sfp_core::result_folder::ResultFolder;

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
    /// How much of the mask the diffuse model cannot explain (absent in
    /// records written before it was measured).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beyond_diffuse: Option<BeyondDiffuse>,
    /// The mask pixels without usable data, the same for every method
    /// (absent from records written before it was counted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unusable: Option<Unusable>,
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
    /// The record in the result folder `result`, if it has one.
    pub fn read(result: &ResultFolder) -> Result<Option<RunRecord>> {
        result.read_run()
    }

    /// The view recorded in `result`'s run record, when it records one.
    pub fn read_view(result: &ResultFolder) -> Result<Option<ViewRecord>> {
        Ok(result.read_run::<Provenance>()?.and_then(|p| p.view))
    }
}
