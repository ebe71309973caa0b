//! Every registered method's declaration and options as text: the
//! `sfp reconstruct --help` listing and the README's option table. Both are
//! generated from the methods' declarations, so they cannot drift from the
//! code; a test fails while the README's table differs from this one.

use crate::method::About;
use crate::methods::{ABOUT, options_of};
use crate::options::{OptionDoc, Options};
use crate::shared_options::SharedOptions;

/// The options of `about`'s method with their defaults: the shared ones
/// it reads, then its own.
fn options(about: &About) -> Vec<OptionDoc> {
    options_of(about.name).expect("a registered method has options")
}

/// Its own options alone.
fn own(about: &About) -> Vec<OptionDoc> {
    let shared = about.shared.len();
    options(about).split_off(shared)
}

/// `name = default` of each shared option `about`'s method reads.
fn shared_defaults(about: &About) -> Vec<String> {
    options(about)[..about.shared.len()]
        .iter()
        .map(|o| format!("{} = {}", o.name, o.default_text()))
        .collect()
}

/// A shared option: its name, doc and, per method that reads it, its
/// default.
struct SharedRow {
    name: &'static str,
    doc: &'static str,
    defaults: Vec<(&'static str, String)>,
}

/// Every shared option's row.
fn shared_rows() -> Vec<SharedRow> {
    SharedOptions::FIELDS
        .iter()
        .map(|f| {
            let defaults = ABOUT
                .iter()
                .filter_map(|a| {
                    let o = options(a).into_iter().find(|o| o.name == f.name)?;
                    a.shared
                        .contains(&f.name)
                        .then(|| (a.name, o.default_text()))
                })
                .collect();
            SharedRow {
                name: f.name,
                doc: f.doc,
                defaults,
            }
        })
        .collect()
}

/// `w/o` switches of a method: `parg = false` (PARG), ….
fn ablations(about: &About) -> String {
    let switches: Vec<String> = about
        .ablations
        .iter()
        .map(|a| {
            let off = options(about)
                .iter()
                .find(|o| o.name == a.option)
                .map_or("false", |o| {
                    if o.default.is_boolean() {
                        "false"
                    } else if o.default.is_string() {
                        "\"off\""
                    } else {
                        "0"
                    }
                });
            format!("`{} = {off}` ({})", a.option, a.step)
        })
        .collect();
    switches.join(", ")
}

/// The README's section: the shared options' table, then one table per
/// method of its own options.
pub fn markdown() -> String {
    let mut out = String::from(
        "\n### Shared options\n\nOptions several methods read, declared once \
         (`reconstruct/src/shared_options.rs`).\n\n\
         | option | default per method | meaning |\n|---|---|---|\n",
    );
    for SharedRow {
        name,
        doc,
        defaults,
    } in shared_rows()
    {
        let defaults: Vec<String> = defaults.iter().map(|(m, d)| format!("{m} `{d}`")).collect();
        out += &format!(
            "| `{name}` | {} | {} |\n",
            defaults.join(", "),
            doc.replace('|', "\\|")
        );
    }
    for about in ABOUT {
        out += &format!(
            "\n### `{}`: {}\n\n{}.\n\nShared options: {}.\n",
            about.name,
            about.display,
            about.paper,
            about
                .shared
                .iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        let own = own(about);
        if !own.is_empty() {
            out += "\n| option | default | meaning |\n|---|---|---|\n";
        }
        for o in own {
            out += &format!(
                "| `{}` | `{}` | {} |\n",
                o.name,
                o.default_text(),
                o.doc.replace('|', "\\|")
            );
        }
        if !about.ablations.is_empty() {
            out += &format!("\nAblation switches: {}.\n", ablations(about));
        }
    }
    out
}

/// The `--help` listing: the shared options, then each method with the
/// shared options it reads and each of its own options, with defaults and
/// meanings.
pub fn text() -> String {
    let mut out = String::from(
        "Methods and their options (`--set NAME=VALUE` or a `--config` file; \
         defaults after `=`).\n\nShared options:\n",
    );
    for SharedRow { name, doc, .. } in shared_rows() {
        out += &format!("  {name}\n      {doc}\n");
    }
    for about in ABOUT {
        out += &format!("\n{} ({}): {}.\n", about.name, about.display, about.paper);
        out += &format!("  shared: {}\n", shared_defaults(about).join(", "));
        for o in own(about) {
            out += &format!("  {} = {}\n      {}\n", o.name, o.default_text(), o.doc);
        }
        if !about.ablations.is_empty() {
            out += &format!(
                "  ablation switches: {}\n",
                ablations(about).replace('`', "")
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const BEGIN: &str = "<!-- method options: generated from the methods' declarations \
                         (reconstruct/src/listing.rs) -->\n";
    const END: &str = "<!-- end of method options -->";

    #[test]
    fn the_readme_lists_the_options_of_the_code() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md");
        let readme = std::fs::read_to_string(path).unwrap();
        let start = readme.find(BEGIN).expect("README: option table markers") + BEGIN.len();
        let end = start + readme[start..].find(END).expect("README: end marker");
        let want = markdown();
        assert!(
            readme[start..end] == want,
            "README.md's method options differ from the code's; between the markers put:\n{want}"
        );
    }

    #[test]
    fn every_option_of_every_method_is_listed() {
        for config in crate::methods::MethodConfig::defaults() {
            let listed: Vec<&str> = options(config.about()).iter().map(|o| o.name).collect();
            let value = config.options_value();
            let keys: Vec<&str> = value
                .as_object()
                .unwrap()
                .keys()
                .map(|k| k.as_str())
                .collect();
            let mut sorted = listed.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, keys, "{}", config.name());
            for a in config.about().ablations {
                assert!(
                    listed.contains(&a.option),
                    "{}: {}",
                    config.name(),
                    a.option
                );
            }
        }
        assert!(text().contains("shading_sense = 2.0"));
        assert!(text().contains("shared: eta = 1.15, light = \"estimate\", seed = 0"));
    }
}
