//! Every method, and the list that registers them. A method is one file
//! (here; SMSfP has a folder of its own, `smsfp`) declaring its name,
//! display name, paper, parameter struct and ablation switches
//! ([`Declared`]); the line `mod file::Type` below declares its module and
//! registers it. [`MethodConfig`] (one variant per method, in the order
//! reports list them) and [`METHODS`] are generated from the list.

use crate::method::{About, Declared, Method};
use crate::options::{OptionDoc, Options};
use crate::smsfp::Smsfp;
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

            /// The options of the method, without its `method` field.
            pub fn options_value(&self) -> serde_json::Value {
                match self {
                    $(MethodConfig::$ty(m) => serde_json::to_value(m),)*
                }
                .expect("method parameters serialise")
            }

            /// The method `name` from its options (no `method` field),
            /// validated; an unknown method or option, or a value out of
            /// range, is an error naming it.
            pub fn parse(name: &str, options: serde_json::Value) -> Result<MethodConfig> {
                let invalid = |e: serde_json::Error| Error::invalid(format!("method '{name}': {e}"));
                $(if name == <$ty as Declared>::ABOUT.name {
                    let method: $ty = serde_json::from_value(options).map_err(invalid)?;
                    method
                        .validate()
                        .map_err(|e| Error::invalid(format!("method '{name}': {e}")))?;
                    return Ok(MethodConfig::$ty(method));
                })*
                Err(Error::invalid(format!(
                    "unknown method '{name}' (known: {})",
                    METHODS.join(", ")
                )))
            }
        }

        /// The options of the method `name` with their defaults and docs.
        pub fn options_of(name: &str) -> Option<Vec<OptionDoc>> {
            $(if name == <$ty as Declared>::ABOUT.name {
                return Some(<$ty as Options>::documented());
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
}
