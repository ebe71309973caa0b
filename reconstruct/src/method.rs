//! The interface every reconstruction method implements, so the CLI, the
//! benchmarks and the tests can run any method the same way, and the
//! declaration each method file makes about itself (name, display name,
//! paper, ablation switches; its options come from its parameter struct)
//! that the registry, the CLI, the report and the README derive from.

use crate::input::Input;
use crate::method_record::MethodRecord;
use crate::options::Options;
use crate::shared_options::SharedOptions;
use crate::specular::share::SpecularReading;
use serde::de::DeserializeOwned;
use serde_json::Value;
use sfp_core::{Error, Image, NormalMap, Result};

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
    /// and their scores: the method's part of `run.json`.
    pub run: MethodRecord,
    /// Method-specific pictures written beside the normals (e.g. SMSfP's
    /// segmentation).
    pub pictures: Vec<Picture>,
    /// What was read as specular (the `specular` option; `None` when
    /// off): `specular.png`, `specular.exr`, and scored in `metrics.json`.
    pub specular: Option<SpecularReading>,
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
    /// Reconstructs the surface seen in `input`.
    fn reconstruct(&self, input: &Input) -> Result<Reconstruction>;
}

/// A method as its file declares it: the parameter struct is the method
/// (serde, with its defaults and an `Options` doc for every field of its
/// own, and the [`SharedOptions`] as a field serde skips) and [`About`] says
/// the rest. One line in `methods/mod.rs` registers it.
pub trait Declared:
    Method + Options + Clone + std::fmt::Debug + DeserializeOwned + Send + Sync + 'static
{
    const ABOUT: About;

    /// Checks every option's value (ranges, finiteness), the shared ones
    /// included, so a bad value is refused where the configuration is read,
    /// before any work.
    fn validate(&self) -> Result<()>;

    /// The shared options it holds (those of `ABOUT.shared` are read).
    fn shared(&self) -> &SharedOptions;

    /// The same, to set.
    fn shared_mut(&mut self) -> &mut SharedOptions;
}

/// What a method says about itself.
#[derive(Clone, Copy, Debug)]
pub struct About {
    /// Short lower-case name: `--method`, a sweep's `method`, `run.json`.
    pub name: &'static str,
    /// Its name in tables and reports (`Smith`, `SMSfP`).
    pub display: &'static str,
    /// The paper it implements.
    pub paper: &'static str,
    /// The shared options it reads ([`SharedOptions`] fields): a
    /// configuration may set these beside the method's own.
    pub shared: &'static [&'static str],
    /// The options that switch one of its steps off for an ablation.
    pub ablations: &'static [Ablation],
}

/// A step a configuration can switch off, and its name in the report
/// (`w/o PARG`).
#[derive(Clone, Copy, Debug)]
pub struct Ablation {
    /// The option: a switch set to `false` (or `"off"`), or a weight set
    /// to 0.
    pub option: &'static str,
    /// The step's name in the report.
    pub step: &'static str,
}

impl Ablation {
    /// The step named `step` in reports, switched off by `option`.
    pub const fn new(option: &'static str, step: &'static str) -> Ablation {
        Ablation { option, step }
    }

    /// Whether the option's `value` in a configuration switches the step off.
    pub fn is_off(&self, value: &Value) -> bool {
        value.as_bool() == Some(false)
            || value.as_f64() == Some(0.0)
            || value.as_str() == Some("off")
    }
}

/// Largest Laplacian smoothness weight `λ` a method accepts: the weight's
/// square against data rows of order 1, so beyond it the data hardly count
/// (and near 1e150 its square overflows, a singular system).
pub const LAMBDA_MAX: f64 = 1e6;

/// Checks a smoothness weight: finite, in `[0, LAMBDA_MAX]`.
pub fn validate_lambda(lambda: f64) -> Result<()> {
    if (0.0..=LAMBDA_MAX).contains(&lambda) {
        return Ok(());
    }
    let shown = if lambda.abs() >= LAMBDA_MAX {
        format!("{lambda:e}")
    } else {
        lambda.to_string()
    };
    Err(Error::invalid(format!(
        "lambda {shown} is outside [0, {LAMBDA_MAX:e}]: beyond it the smoothness term \
         drowns the data (0 is none; the methods' default is 0.1)"
    )))
}
