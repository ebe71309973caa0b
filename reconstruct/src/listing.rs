//! Every registered method's declaration and options as text: the
//! `sfp reconstruct --help` listing and the README's option table. Both are
//! generated from the methods' declarations, so they cannot drift from the
//! code; a test fails while the README's table differs from this one.

use crate::method::About;
use crate::registry::{ABOUT, options_of};

/// The options of `about`'s method with their defaults.
fn options(about: &About) -> Vec<crate::options::OptionDoc> {
    options_of(about.name).expect("a registered method has options")
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
                .map_or(
                    "false",
                    |o| if o.default.is_boolean() { "false" } else { "0" },
                );
            format!("`{} = {off}` ({})", a.option, a.step)
        })
        .collect();
    switches.join(", ")
}

/// The README's section: one table per method.
pub fn markdown() -> String {
    let mut out = String::new();
    for about in ABOUT {
        out += &format!(
            "\n### `{}`: {}\n\n{}.\n\n| option | default | meaning |\n|---|---|---|\n",
            about.name, about.display, about.paper
        );
        for o in options(about) {
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

/// The `--help` listing: each method, then each option with its default
/// and meaning.
pub fn text() -> String {
    let mut out = String::from(
        "Methods and their options (`--set NAME=VALUE` or a `--config` file; \
         defaults after `=`):\n",
    );
    for about in ABOUT {
        out += &format!("\n{} ({}): {}.\n", about.name, about.display, about.paper);
        for o in options(about) {
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
        for config in crate::registry::MethodConfig::defaults() {
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
    }
}
