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
    /// Method-specific pictures written beside the normals (e.g. SMSfP's
    /// segmentation).
    pub pictures: Vec<Picture>,
}

/// A picture a method writes into its result folder, with its file name.
#[derive(Clone, Debug)]
pub enum Picture {
    /// 8-bit RGB PNG.
    Rgb(&'static str, Image<[u8; 3]>),
    /// 16-bit grayscale PNG.
    Gray16(&'static str, Image<u16>),
}

/// A shape-from-polarization method.
pub trait Method {
    /// Short lower-case name used on the command line and in `run.json`.
    fn name(&self) -> &str;
    /// Reconstructs the surface seen in `input`.
    fn reconstruct(&self, input: &Input) -> Result<Reconstruction>;
}

/// Largest refractive index a method accepts: above every common dielectric
/// (diamond ≈ 2.42); beyond it `η²` and `η⁴` in the diffuse model lose
/// meaning long before they overflow.
pub const ETA_MAX: f64 = 3.0;

/// Checks a refractive index a method assumes: finite, in `(1, ETA_MAX]`.
pub fn validate_eta(eta: f64) -> Result<()> {
    sfp_core::fresnel::check_eta(eta, ETA_MAX)
}
