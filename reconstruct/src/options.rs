//! A method's options as data: the name and doc of each field of its
//! parameter struct (`#[derive(Options)]`, written once on the field) with
//! the default its `Default` gives. The `--help` listing, the README's
//! option table and any other front end read them from here.

use serde::Serialize;
use serde_json::Value;

pub use sfp_reconstruct_derive::Options;

/// One option as the derive lists it.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    /// The field name: the key in a configuration (`--set NAME=VALUE`).
    pub name: &'static str,
    /// The field's `///` doc, as one paragraph.
    pub doc: &'static str,
}

/// A parameter struct whose options are listed (`#[derive(Options)]`).
pub trait Options: Default + Serialize {
    /// Every settable field, in declaration order.
    const FIELDS: &'static [Field];

    /// Every option with its default value.
    fn documented() -> Vec<OptionDoc> {
        let defaults = serde_json::to_value(Self::default()).expect("default parameters serialise");
        Self::FIELDS
            .iter()
            .map(|f| OptionDoc {
                name: f.name,
                default: defaults.get(f.name).cloned().unwrap_or(Value::Null),
                doc: f.doc,
            })
            .collect()
    }
}

/// An option with its default.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionDoc {
    pub name: &'static str,
    pub default: Value,
    pub doc: &'static str,
}

impl OptionDoc {
    /// The default as a TOML value, as a configuration file or `--set`
    /// writes it: `1.5`, `true`, `"estimate"`, `{ tau = 2.0, … }`.
    pub fn default_text(&self) -> String {
        toml_text(&self.default)
    }
}

fn toml_text(v: &Value) -> String {
    match v {
        Value::Null => "none".into(),
        Value::Bool(_) | Value::Number(_) | Value::String(_) => v.to_string(),
        Value::Array(items) => {
            let items: Vec<String> = items.iter().map(toml_text).collect();
            format!("[{}]", items.join(", "))
        }
        Value::Object(map) => {
            let items: Vec<String> = map
                .iter()
                .map(|(k, v)| format!("{k} = {}", toml_text(v)))
                .collect();
            format!("{{ {} }}", items.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Demonstrates the derive: doc paragraphs, skipped fields, defaults.
    #[derive(Default, Serialize, Options)]
    struct Example {
        /// Refractive index
        /// of the surface.
        eta: f64,
        /// Inner table.
        inner: Inner,
        #[serde(skip)]
        #[allow(dead_code)]
        cache: Vec<u8>,
    }

    #[derive(Default, Serialize)]
    struct Inner {
        scales: Vec<usize>,
        name: String,
    }

    #[test]
    fn options_list_the_fields_with_docs_and_defaults() {
        let docs = Example::documented();
        assert_eq!(docs.len(), 2);
        assert_eq!(docs[0].name, "eta");
        assert_eq!(docs[0].doc, "Refractive index of the surface.");
        assert_eq!(docs[0].default_text(), "0.0");
        assert_eq!(docs[1].default_text(), "{ name = \"\", scales = [] }");
    }
}
