//! The interface every reconstruction method implements, so the CLI, the
//! benchmarks and the tests can run any method the same way.

use crate::input::Input;
use sfp_core::{Image, NormalMap, Result};

/// What a method returns: normals, a height map and a record of the run.
#[derive(Clone, Debug)]
pub struct Reconstruction {
    /// Unit normals in the camera frame; `[0, 0, 0]` outside the mask.
    pub normals: NormalMap,
    /// Height `z` (towards the camera, pixel units), NaN outside the mask.
    /// Each connected mask component has zero mean height (the constant of
    /// integration is not observable).
    pub height: Image<f32>,
    /// Parameters, timings (assembly vs solve, in seconds), light candidates
    /// and their scores: written verbatim to `run.json`.
    pub run: serde_json::Value,
}

/// A shape-from-polarization method.
pub trait Method {
    /// Short lower-case name used on the command line and in `run.json`.
    fn name(&self) -> &str;
    /// Reconstructs the surface seen in `input`.
    fn reconstruct(&self, input: &Input) -> Result<Reconstruction>;
}
