//! The options several methods share, declared once: the refractive index,
//! the light, the light estimator's seed and the specular model. A method
//! holds them as its `shared` field and names in its [`About`] which of them
//! it reads; the registry accepts exactly those keys beside the method's own
//! options, so a configuration writes `{ method = "smith", eta = 1.3 }` as
//! before and a sweep sets `eta` through [`SharedOptions`] without knowing
//! the method.
//!
//! [`About`]: crate::method::About

use crate::light::LightSource;
use crate::options::{OptionDoc, Options};
use crate::specular::model::SpecularModel;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use sfp_core::{Error, Result};

/// Largest refractive index a method accepts: above every common dielectric
/// (diamond ≈ 2.42); beyond it `η²` and `η⁴` in the diffuse model lose
/// meaning long before they overflow.
pub const ETA_MAX: f64 = 3.0;

/// Checks a refractive index a method assumes: finite, in `(1, ETA_MAX]`.
pub fn validate_eta(eta: f64) -> Result<()> {
    sfp_core::fresnel::check_eta(eta, ETA_MAX)
}

/// The options shared by the methods (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Options)]
#[serde(default, deny_unknown_fields)]
pub struct SharedOptions {
    /// Refractive index assumed for the zenith inversion, in `(1, 3]`
    /// (SMSfP: where its search starts, and the one index without
    /// refinement). The baselines default to their reference code's 1.5,
    /// SMSfP to its paper's 1.15.
    pub eta: f64,
    /// The light: `"estimate"`, `"estimate_ambient"`, `{ direction = [x, y,
    /// z] }` (intensity estimated) or `{ known = { light = [x, y, z], albedo
    /// = a } }`.
    pub light: LightSource,
    /// Seed of the light estimator's starting lights.
    pub seed: u64,
    /// Specular reflection: `"off"` (every pixel diffuse), `"auto"`
    /// (labelled from the data) or a grayscale PNG mask's path: specular
    /// where at least half the mask's brightest value, so 0/255, 0/1 (a
    /// saved NumPy bool), 0/127 and 16-bit masks all read as drawn; a mask
    /// of zeros labels nothing, with a warning.
    pub specular: SpecularModel,
}

impl Default for SharedOptions {
    fn default() -> Self {
        SharedOptions {
            eta: 1.5,
            light: LightSource::Estimate,
            seed: 0,
            specular: SpecularModel::Off,
        }
    }
}

impl SharedOptions {
    /// Whether `key` names a shared option.
    pub fn has(key: &str) -> bool {
        Self::FIELDS.iter().any(|f| f.name == key)
    }

    /// Checks every value: η in `(1, 3]`, a known light finite with albedo
    /// > 0.
    pub fn validate(&self) -> Result<()> {
        validate_eta(self.eta)?;
        self.light.validate()
    }

    /// These options with `given` (shared keys only) over them: what a
    /// configuration file, `--set` or a sweep wrote, read into types.
    pub fn overlaid(&self, given: Map<String, Value>) -> Result<SharedOptions> {
        let Value::Object(mut all) = serde_json::to_value(self).expect("options serialise") else {
            unreachable!("a struct serialises to an object")
        };
        all.extend(given);
        serde_json::from_value(Value::Object(all)).map_err(|e| Error::invalid(e.to_string()))
    }

    /// The values of `keys` (shared option names), as a configuration
    /// writes them.
    pub fn values(&self, keys: &[&str]) -> Map<String, Value> {
        let Value::Object(all) = serde_json::to_value(self).expect("options serialise") else {
            unreachable!("a struct serialises to an object")
        };
        all.into_iter()
            .filter(|(k, _)| keys.contains(&k.as_str()))
            .collect()
    }

    /// The documentation of `keys` with these values as their defaults, in
    /// declaration order.
    pub fn documented(&self, keys: &[&str]) -> Vec<OptionDoc> {
        let values = self.values(keys);
        Self::FIELDS
            .iter()
            .filter(|f| keys.contains(&f.name))
            .map(|f| OptionDoc {
                name: f.name,
                default: values[f.name].clone(),
                doc: f.doc,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn given_keys_are_read_over_the_defaults_and_checked() {
        let base = SharedOptions {
            eta: 1.15,
            ..SharedOptions::default()
        };
        let given = Map::from_iter([("seed".to_string(), Value::from(7))]);
        let read = base.overlaid(given).unwrap();
        assert_eq!((read.eta, read.seed), (1.15, 7));
        let bad = Map::from_iter([("specular".to_string(), Value::from(""))]);
        assert!(base.overlaid(bad).is_err());
        let far = SharedOptions {
            eta: 3.5,
            ..base.clone()
        };
        assert!(far.validate().unwrap_err().to_string().contains("3.5"));
        assert_eq!(
            base.values(&["eta", "specular"]),
            Map::from_iter([
                ("eta".to_string(), Value::from(1.15)),
                ("specular".to_string(), Value::from("off")),
            ])
        );
        let docs = base.documented(&["specular", "eta"]);
        assert_eq!(
            docs.iter().map(|d| d.name).collect::<Vec<_>>(),
            ["eta", "specular"]
        );
    }
}
