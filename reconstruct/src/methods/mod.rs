//! Every method, and the list that registers them. A method is one file
//! (here; SMSfP has a folder of its own, `smsfp`) declaring its name,
//! display name, paper, parameter struct and ablation switches
//! ([`Declared`]); the line `mod file::Type` below declares its module and
//! registers it. [`MethodConfig`] (one variant per method, in the order
//! reports list them) and [`METHODS`] are generated from the list.

use crate::method::{About, Declared, Method};
use crate::options::{OptionDoc, Options};
use crate::shared_options::SharedOptions;
use crate::smsfp::Smsfp;
use serde_json::{Map, Value};
use sfp_core::{Error, Result};

/// Declares the modules of the listed methods (`mod file::Type`; a bare
/// `Type` is a method in scope already) and generates the registry's enum.
macro_rules! registry {
    (@munch [$($done:tt)*]) => { registry!(@emit $($done)*); };
    (@munch [$($done:tt)*] mod $module:ident :: $ty:ident, $($rest:tt)*) => {
        pub mod $module;
        pub use $module::$ty;
        registry!(@munch [$($done)* $ty] $($rest)*);
    };
    (@munch [$($done:tt)*] $ty:ident, $($rest:tt)*) => {
        registry!(@munch [$($done)* $ty] $($rest)*);
    };
    (@emit $($ty:ident)*) => {
        /// A method and its parameters: serialised as the method's options
        /// with its name as `method` (`{ method = "smith", eta = 1.5 }`).
        #[derive(Clone, Debug)]
        pub enum MethodConfig {
            $($ty($ty),)*
        }

        /// Every registered method name, in the order reports list them.
        pub const METHODS: &[&str] = &[$(<$ty as Declared>::ABOUT.name),*];

        /// Every registered method's declaration, in the order of [`METHODS`].
        pub const ABOUT: &[About] = &[$(<$ty as Declared>::ABOUT),*];

        impl MethodConfig {
            /// The method's declaration.
            pub fn about(&self) -> &'static About {
                match self {
                    $(MethodConfig::$ty(_) => &<$ty as Declared>::ABOUT,)*
                }
            }

            /// The runnable method.
            pub fn build(&self) -> Box<dyn Method + Send + Sync> {
                match self {
                    $(MethodConfig::$ty(m) => Box::new(m.clone()),)*
                }
            }

            /// The options of the method, without its `method` field: its
            /// own and the shared ones it reads.
            pub fn options_value(&self) -> serde_json::Value {
                match self {
                    $(MethodConfig::$ty(m) => with_shared(serde_json::to_value(m), m),)*
                }
            }

            /// The shared options of the method.
            pub fn shared(&self) -> &SharedOptions {
                match self {
                    $(MethodConfig::$ty(m) => m.shared(),)*
                }
            }

            /// The same, to set (validate after: [`MethodConfig::validate`]).
            fn shared_mut(&mut self) -> &mut SharedOptions {
                match self {
                    $(MethodConfig::$ty(m) => m.shared_mut(),)*
                }
            }

            /// Checks every option's value.
            pub fn validate(&self) -> Result<()> {
                match self {
                    $(MethodConfig::$ty(m) => m.validate(),)*
                }
                .map_err(|e| Error::invalid(format!("method '{}': {e}", self.about().name)))
            }

            /// The method `name` from its options (no `method` field),
            /// validated; an unknown method or option, or a value out of
            /// range, is an error naming it.
            pub fn parse(name: &str, options: serde_json::Value) -> Result<MethodConfig> {
                $(if name == <$ty as Declared>::ABOUT.name {
                    let (own, shared) = split::<$ty>(options)?;
                    let invalid =
                        |e: serde_json::Error| Error::invalid(format!("method '{name}': {e}"));
                    let mut method: $ty = serde_json::from_value(own).map_err(invalid)?;
                    let read = method.shared().overlaid(shared);
                    *method.shared_mut() =
                        read.map_err(|e| Error::invalid(format!("method '{name}': {e}")))?;
                    let config = MethodConfig::$ty(method);
                    config.validate()?;
                    return Ok(config);
                })*
                Err(Error::invalid(format!(
                    "unknown method '{name}' (known: {})",
                    METHODS.join(", ")
                )))
            }
        }

        /// The options of the method `name` with their defaults and docs:
        /// the shared ones it reads, then its own.
        pub fn options_of(name: &str) -> Option<Vec<OptionDoc>> {
            $(if name == <$ty as Declared>::ABOUT.name {
                let about = <$ty as Declared>::ABOUT;
                let mut docs = <$ty>::default().shared().documented(about.shared);
                docs.extend(<$ty as Options>::documented());
                return Some(docs);
            })*
            None
        }
    };
    ($($entries:tt)*) => { registry!(@munch [] $($entries)*); };
}

registry! {
    mod atkinson::Atkinson,
    mod mahmoud::Mahmoud,
    mod smith::Smith,
    Smsfp,
    mod yu2017::Yu2017,
}

/// A method's options (`{ key = value }`) parted into its own, for its
/// struct, and the shared ones it reads; any other key is an error naming
/// it and the method's options.
fn split<M: Declared>(options: Value) -> Result<(Value, Map<String, Value>)> {
    let name = M::ABOUT.name;
    let Value::Object(options) = options else {
        return Err(Error::invalid(format!(
            "method '{name}': options are a table, not {options}"
        )));
    };
    let own_names = || M::FIELDS.iter().map(|f| f.name);
    let (mut own, mut shared) = (Map::new(), Map::new());
    for (key, value) in options {
        if own_names().any(|n| n == key) {
            own.insert(key, value);
        } else if M::ABOUT.shared.contains(&key.as_str()) {
            shared.insert(key, value);
        } else {
            let known: Vec<&str> = M::ABOUT.shared.iter().copied().chain(own_names()).collect();
            return Err(Error::invalid(format!(
                "method '{name}': unknown option `{key}` (its options: {})",
                known.join(", ")
            )));
        }
    }
    Ok((Value::Object(own), shared))
}

/// A method's own options serialised, with the shared ones it reads.
fn with_shared<M: Declared>(own: serde_json::Result<Value>, method: &M) -> Value {
    let Ok(Value::Object(mut own)) = own else {
        unreachable!("a method's options serialise to a table")
    };
    own.extend(method.shared().values(M::ABOUT.shared));
    Value::Object(own)
}

/// Whether the method `name` has the option `key` (its own or a shared one
/// it reads).
pub fn has_option(name: &str, key: &str) -> bool {
    options_of(name).is_some_and(|docs| docs.iter().any(|d| d.name == key))
}

impl MethodConfig {
    /// The configuration with shared options `set` on it, validated: a
    /// sweep's `method_eta` sets `eta` this way.
    pub fn with_shared(&self, set: impl FnOnce(&mut SharedOptions)) -> Result<MethodConfig> {
        let mut config = self.clone();
        set(config.shared_mut());
        config.validate()?;
        Ok(config)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shared_name_is_a_shared_option_and_no_own_option() {
        for about in ABOUT {
            for key in about.shared {
                assert!(SharedOptions::has(key), "{}: {key}", about.name);
            }
            let docs = options_of(about.name).unwrap();
            let mut names: Vec<&str> = docs.iter().map(|d| d.name).collect();
            let all = names.len();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), all, "{}: an option declared twice", about.name);
        }
    }
}
