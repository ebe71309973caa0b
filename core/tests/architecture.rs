//! The workspace's shape, checked on its sources: no import circle between
//! the modules of any crate, no module importing one of a higher layer (the
//! layer tables of docs/architecture.md), and no source file over 1,000
//! lines. It reads files only, so it lives in the crate
//! every other builds first.
//!
//! A module's imports are what its code names: `use` lines and qualified
//! paths (`crate::…`, `super::…`, `self::…`, a child module, or a name a
//! `use` bound to a module), each resolved to the module that *defines* the
//! item, through re-exports (a `pub use` is a name, not a dependency: a
//! crate root that re-exports a layer does not sit above it). Comments,
//! strings and `#[cfg(test)]` modules are left out: tests may reach across
//! layers. `mod` declarations are not imports.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const CRATES: [&str; 5] = ["core", "renderer", "reconstruct", "benchmarks", "cli"];
const MAX_LINES: usize = 1000;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if path.file_name().is_some_and(|n| n != "target") {
                rust_files(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn no_source_file_is_over_a_thousand_lines() {
    let mut files = Vec::new();
    for krate in CRATES.iter().chain(&["fuzz"]) {
        rust_files(&workspace().join(krate), &mut files);
    }
    assert!(files.len() > 50, "found only {} source files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let lines = std::fs::read_to_string(f).ok()?.lines().count();
            (lines > MAX_LINES).then(|| format!("{} ({lines} lines)", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "split by concept: {}", long.join(", "));
}

#[test]
fn no_crate_has_an_import_circle() {
    let mut report = String::new();
    for krate in CRATES {
        let graph = ModuleGraph::of_crate(&workspace().join(krate).join("src"));
        assert!(graph.modules.len() > 3, "{krate}: no modules found");
        let imports: usize = graph.modules.values().map(|m| m.imports.len()).sum();
        println!(
            "{krate}: {} modules, {imports} imports",
            graph.modules.len()
        );
        for cycle in graph.cycles() {
            report.push_str(&format!("{krate}: {}\n", graph.describe(&cycle)));
        }
    }
    assert!(report.is_empty(), "import circles:\n{report}");
}

#[test]
fn a_circle_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir(src.join("bsdf")).unwrap();
    let files = [
        (
            "lib.rs",
            "pub mod a;\npub mod b;\npub mod c;\npub mod d;\npub mod e;\npub mod bsdf;\npub use a::Thing;\n",
        ),
        (
            "a.rs",
            "use crate::b::f;\n/// [`crate::c`] in a comment is no import\npub struct Thing;\n",
        ),
        (
            "b.rs",
            "pub fn f() { let _ = \"crate::c::g\"; crate::c::g(); }\n",
        ),
        (
            "c.rs",
            "pub fn g() { let _ = crate::Thing; }\n#[cfg(test)]\nmod tests {\n    use crate::bsdf::Z;\n}\n",
        ),
        (
            "bsdf/mod.rs",
            "mod lobe;\npub use lobe::Z;\npub struct Y;\n",
        ),
        ("bsdf/lobe.rs", "use super::Y;\npub struct Z;\n"),
        (
            "d.rs",
            "pub fn h() {}\n#[cfg(test)]\npub(crate) mod tests {\n    use crate::e::*;\n}\n",
        ),
        ("e.rs", "use crate::d::h;\npub fn k() { h() }\n"),
    ];
    for (name, text) in files {
        std::fs::write(src.join(name), text).unwrap();
    }
    let graph = ModuleGraph::of_crate(src);
    let cycles: Vec<String> = graph.cycles().iter().map(|c| graph.describe(c)).collect();
    // a → b → c → a (through the root's re-export of `a::Thing`); the
    // re-export `bsdf::Z` and the test module's import (d → e → d) make none.
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert!(
        cycles[0].contains("a.rs:1") && cycles[0].contains("c.rs:1"),
        "{}",
        cycles[0]
    );
}

#[test]
fn no_module_imports_a_higher_layer() {
    let doc_path = workspace().join("docs/architecture.md");
    let doc = std::fs::read_to_string(&doc_path).unwrap();
    let mut report = String::new();
    for krate in CRATES {
        let layers = match Layers::of_crate(&doc, krate) {
            Ok(layers) => layers,
            Err(e) => {
                report.push_str(&format!("docs/architecture.md: {e}\n"));
                continue;
            }
        };
        let graph = ModuleGraph::of_crate(&workspace().join(krate).join("src"));
        for problem in layers.violations(&graph) {
            report.push_str(&format!("{krate}: {problem}\n"));
        }
    }
    assert!(
        report.is_empty(),
        "layers (docs/architecture.md):\n{report}"
    );
}

#[test]
fn an_upward_import_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir(src.join("kinds")).unwrap();
    let files = [
        (
            "lib.rs",
            "pub mod basic;\npub mod kinds;\npub mod scene;\n#[cfg(test)]\nmod support;\n",
        ),
        (
            "basic.rs",
            "pub struct B;\n\npub fn f() -> crate::scene::S { todo!() }\n",
        ),
        ("kinds/mod.rs", "pub mod one;\nuse crate::basic::B;\n"),
        ("kinds/one.rs", "use super::super::basic::B;\n"),
        ("scene.rs", "use crate::kinds::one;\npub struct S;\n"),
        ("support.rs", "use crate::scene::S;\n"),
    ];
    for (name, text) in files {
        std::fs::write(src.join(name), text).unwrap();
    }
    let doc = "# Architecture\n\n## fake\n\n| layer | modules |\n| --- | --- |\n\
               | 1 | `basic` |\n| 2 | `kinds/` |\n| 3 | `scene` · `gone` |\n\n## other\n\n\
               | layer | modules |\n| --- | --- |\n| 1 | `basic` |\n";
    let layers = Layers::of_crate(doc, "fake").unwrap();
    let problems = layers.violations(&ModuleGraph::of_crate(src));
    // basic (1) → scene (3) is the one upward import; `gone` names no
    // module; the test-only `support` needs no layer.
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(
        problems[0].contains("basic.rs:3")
            && problems[0].contains("`basic` (layer 1)")
            && problems[0].contains("`scene` (layer 3)"),
        "{}",
        problems[0]
    );
    assert!(problems[1].contains("`gone`"), "{}", problems[1]);
    let unlisted = Layers::of_crate(doc, "other").unwrap();
    let problems = unlisted.violations(&ModuleGraph::of_crate(src));
    assert!(
        problems
            .iter()
            .any(|p| p.contains("scene.rs") && p.contains("no layer")),
        "{problems:?}"
    );
    assert!(Layers::of_crate(doc, "missing").is_err());
}

/// A crate's layers as docs/architecture.md states them: under the crate's
/// `## name` heading, a table `| layer | modules |` whose rows give a
/// number and module paths in backticks (`lights/` or `methods/atkinson`).
/// An entry holds the module and every module below it; the longest entry
/// that holds a module gives its layer. The crate root only declares
/// modules and sits outside the layers.
struct Layers {
    /// Module path (`methods::atkinson`) → layer.
    entries: BTreeMap<String, usize>,
}

impl Layers {
    fn of_crate(doc: &str, krate: &str) -> Result<Layers, String> {
        let heading = format!("## {krate}");
        let mut inside = false;
        let mut entries = BTreeMap::new();
        for line in doc.lines() {
            if line.starts_with("## ") {
                inside = line == heading;
            }
            if !inside || !line.starts_with('|') {
                continue;
            }
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            let Some(Ok(layer)) = cells.get(1).map(|c| c.parse::<usize>()) else {
                continue;
            };
            let modules = cells.get(2).copied().unwrap_or_default();
            for name in modules.split('`').skip(1).step_by(2) {
                let path = name.trim_end_matches('/').replace('/', "::");
                if entries.insert(path, layer).is_some() {
                    return Err(format!("{heading}: `{name}` is in two rows"));
                }
            }
        }
        if entries.is_empty() {
            return Err(format!("{heading}: no `| layer | modules |` table"));
        }
        Ok(Layers { entries })
    }

    /// The layer of a module: its longest entry's.
    fn of(&self, module: &str) -> Option<usize> {
        let mut parts = split(module);
        while !parts.is_empty() {
            if let Some(&layer) = self.entries.get(&join(&parts)) {
                return Some(layer);
            }
            parts.pop();
        }
        None
    }

    /// Imports of a higher layer (`file:line`, both modules and layers),
    /// modules without a layer and entries that name no module.
    fn violations(&self, graph: &ModuleGraph) -> Vec<String> {
        let live = graph.declared();
        let mut out = Vec::new();
        for name in live.iter().filter(|m| !m.is_empty()) {
            let module = &graph.modules[name];
            let Some(layer) = self.of(name) else {
                out.push(format!(
                    "{}: module `{name}` has no layer in its crate's table",
                    shown(&module.file)
                ));
                continue;
            };
            for (target, line) in &module.imports {
                if let Some(above) = self.of(target).filter(|&t| t > layer) {
                    out.push(format!(
                        "{}:{line}: `{name}` (layer {layer}) imports `{target}` (layer {above})",
                        shown(&module.file)
                    ));
                }
            }
        }
        for entry in self.entries.keys() {
            let prefix = format!("{entry}::");
            if !live.iter().any(|m| m == entry || m.starts_with(&prefix)) {
                out.push(format!("the table names `{entry}`, which is no module"));
            }
        }
        out
    }
}

/// A source file's path from the workspace, as in error messages.
fn shown(file: &Path) -> String {
    let root = workspace();
    file.strip_prefix(&root)
        .unwrap_or(file)
        .display()
        .to_string()
}

/// Modules (by path, `""` the crate root) and the modules each one imports.
struct ModuleGraph {
    modules: BTreeMap<String, Module>,
}

struct Module {
    file: PathBuf,
    /// Child modules declared with `mod`.
    children: BTreeSet<String>,
    /// Names bound by `use` lines → the absolute path they name, and
    /// whether the binding is a re-export (`pub use`).
    bindings: BTreeMap<String, (Vec<String>, bool)>,
    /// Imported module → the first line that imports it.
    imports: BTreeMap<String, usize>,
}

fn join(module: &[String]) -> String {
    module.join("::")
}

fn split(module: &str) -> Vec<String> {
    if module.is_empty() {
        Vec::new()
    } else {
        module.split("::").map(String::from).collect()
    }
}

impl ModuleGraph {
    fn of_crate(src: &Path) -> ModuleGraph {
        let mut files = Vec::new();
        rust_files(src, &mut files);
        let mut texts = BTreeMap::new();
        for file in files {
            let rel = file.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if matches!(parts.last().map(String::as_str), Some("mod")) {
                parts.pop();
            }
            if parts == ["lib"] || parts == ["main"] {
                parts.clear();
            }
            if parts.first().is_some_and(|p| p == "bin") {
                continue;
            }
            let text = strip_tests(&code_only(&std::fs::read_to_string(&file).unwrap()));
            texts.insert(join(&parts), (file, text));
        }
        let mut graph = ModuleGraph {
            modules: BTreeMap::new(),
        };
        for (name, (file, text)) in &texts {
            let children = declared_modules(text);
            graph.modules.insert(
                name.clone(),
                Module {
                    file: file.clone(),
                    children,
                    bindings: BTreeMap::new(),
                    imports: BTreeMap::new(),
                },
            );
        }
        // Bindings first (resolving a path may go through any module's).
        let mut uses = BTreeMap::new();
        for (name, (_, text)) in &texts {
            let here = split(name);
            let statements = use_statements(text);
            let mut bindings = BTreeMap::new();
            for (line, public, tree) in &statements {
                for path in expand_use_tree(tree) {
                    if let Some(absolute) = graph.absolute(&here, &path) {
                        let bound = path.last().unwrap().clone();
                        if bound != "*" && bound != "self" {
                            bindings.insert(bound, (absolute.clone(), *public));
                        }
                        uses.entry(name.clone())
                            .or_insert_with(Vec::new)
                            .push((*line, *public, absolute));
                    }
                }
            }
            graph.modules.get_mut(name).unwrap().bindings = bindings;
        }
        // `self::x` and `super::x` of a binding were made absolute above;
        // only now can a path be followed through other modules' bindings.
        for (name, (_, text)) in &texts {
            let here = split(name);
            let mut imports = BTreeMap::new();
            let mut add = |target: Option<String>, line: usize| {
                if let Some(t) = target
                    && t != *name
                {
                    imports.entry(t).or_insert(line);
                }
            };
            for (line, public, absolute) in uses.get(name).into_iter().flatten() {
                if !public {
                    add(graph.defining_module(absolute, 0), *line);
                }
            }
            let without_uses = blank_use_statements(text);
            for (line, path) in qualified_paths(&without_uses) {
                let absolute = graph
                    .absolute(&here, &path)
                    .or_else(|| graph.through_binding(&here, &path));
                if let Some(absolute) = absolute {
                    add(graph.defining_module(&absolute, 0), line);
                }
            }
            graph.modules.get_mut(name).unwrap().imports = imports;
        }
        graph
    }

    /// The modules the build compiles outside tests: the root and those
    /// declared, not under `#[cfg(test)]`, by a module it compiles.
    fn declared(&self) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        let mut todo = vec![String::new()];
        while let Some(name) = todo.pop() {
            let Some(module) = self.modules.get(&name) else {
                continue;
            };
            if out.insert(name.clone()) {
                for child in &module.children {
                    let mut path = split(&name);
                    path.push(child.clone());
                    todo.push(join(&path));
                }
            }
        }
        out
    }

    /// `path` written in module `here` as an absolute path, when it starts
    /// with `crate`, `self`, `super` or a child module of `here`.
    fn absolute(&self, here: &[String], path: &[String]) -> Option<Vec<String>> {
        let mut base = here.to_vec();
        let mut rest = path;
        match path.first()?.as_str() {
            "crate" => {
                base.clear();
                rest = &path[1..];
            }
            "self" => rest = &path[1..],
            "super" => {
                while rest.first().is_some_and(|s| s == "super") {
                    base.pop()?;
                    rest = &rest[1..];
                }
            }
            first => {
                let module = self.modules.get(&join(here))?;
                if !module.children.contains(first) {
                    return None;
                }
            }
        }
        base.extend(rest.iter().cloned());
        Some(base)
    }

    /// `path` whose first segment is a name a `use` line of `here` bound.
    fn through_binding(&self, here: &[String], path: &[String]) -> Option<Vec<String>> {
        let (bound, _) = self.modules.get(&join(here))?.bindings.get(path.first()?)?;
        let mut absolute = bound.clone();
        absolute.extend(path[1..].iter().cloned());
        Some(absolute)
    }

    /// The module that defines what the absolute `path` names, following
    /// re-exports; `None` for paths outside the crate's modules.
    fn defining_module(&self, path: &[String], depth: usize) -> Option<String> {
        if depth > 16 {
            return None;
        }
        let mut module: Vec<String> = Vec::new();
        for (i, segment) in path.iter().enumerate() {
            let mut deeper = module.clone();
            deeper.push(segment.clone());
            if self.modules.contains_key(&join(&deeper)) {
                module = deeper;
                continue;
            }
            let current = self.modules.get(&join(&module))?;
            if let Some((target, _)) = current.bindings.get(segment) {
                let mut next = target.clone();
                next.extend(path[i + 1..].iter().cloned());
                return self.defining_module(&next, depth + 1);
            }
            return Some(join(&module));
        }
        Some(join(&module))
    }

    /// Strongly connected sets of modules larger than one (Tarjan).
    fn cycles(&self) -> Vec<Vec<String>> {
        struct State<'a> {
            graph: &'a ModuleGraph,
            index: BTreeMap<&'a str, usize>,
            low: BTreeMap<&'a str, usize>,
            stack: Vec<&'a str>,
            on_stack: BTreeSet<&'a str>,
            found: Vec<Vec<String>>,
        }
        fn visit<'a>(s: &mut State<'a>, v: &'a str) {
            let i = s.index.len();
            s.index.insert(v, i);
            s.low.insert(v, i);
            s.stack.push(v);
            s.on_stack.insert(v);
            for w in s.graph.modules[v].imports.keys() {
                let Some((w, _)) = s.graph.modules.get_key_value(w) else {
                    continue;
                };
                let w = w.as_str();
                if !s.index.contains_key(w) {
                    visit(s, w);
                    let low = s.low[v].min(s.low[w]);
                    s.low.insert(v, low);
                } else if s.on_stack.contains(w) {
                    let low = s.low[v].min(s.index[w]);
                    s.low.insert(v, low);
                }
            }
            if s.low[v] == s.index[v] {
                let mut component = Vec::new();
                while let Some(w) = s.stack.pop() {
                    s.on_stack.remove(w);
                    component.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    s.found.push(component);
                }
            }
        }
        let mut state = State {
            graph: self,
            index: BTreeMap::new(),
            low: BTreeMap::new(),
            stack: Vec::new(),
            on_stack: BTreeSet::new(),
            found: Vec::new(),
        };
        for v in self.modules.keys() {
            if !state.index.contains_key(v.as_str()) {
                visit(&mut state, v);
            }
        }
        state.found
    }

    /// A circle's imports among its modules, as `file:line → module`.
    fn describe(&self, cycle: &[String]) -> String {
        let mut parts = Vec::new();
        for m in cycle {
            let module = &self.modules[m];
            let file = module.file.file_name().unwrap().to_string_lossy();
            let parent = module
                .file
                .parent()
                .and_then(|p| p.file_name())
                .map(|p| p.to_string_lossy().into_owned())
                .unwrap_or_default();
            for (target, line) in &module.imports {
                if cycle.contains(target) {
                    let target = if target.is_empty() {
                        "crate root"
                    } else {
                        target
                    };
                    parts.push(format!("{parent}/{file}:{line} uses {target}"));
                }
            }
        }
        parts.join("; ")
    }
}

/// The code of a file with comments, string and character literals blanked
/// (newlines kept, so line numbers hold).
fn code_only(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < chars.len() {
                if chars[i] == '/' && chars.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if chars[i] == '*' && chars.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(chars[i]));
                    i += 1;
                }
            }
        } else if c == 'r'
            && (next == Some('#') || next == Some('"'))
            && !ident_char(prev(&chars, i))
        {
            let mut hashes = 0;
            let mut j = i + 1;
            while chars.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if chars.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            out.push('"');
            for _ in i + 1..=j {
                out.push(' ');
            }
            i = j + 1;
            while i < chars.len() {
                if chars[i] == '"' && (0..hashes).all(|k| chars.get(i + 1 + k) == Some(&'#')) {
                    out.push('"');
                    for _ in 0..hashes {
                        out.push(' ');
                    }
                    i += 1 + hashes;
                    break;
                }
                out.push(blank(chars[i]));
                i += 1;
            }
        } else if c == '"' {
            out.push('"');
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < chars.len() {
                    out.push(blank(chars[i]));
                    i += 1;
                }
            }
            out.push('"');
            i += 1;
        } else if c == '\'' && is_char_literal(&chars, i) {
            out.push('\'');
            i += 1;
            while i < chars.len() && chars[i] != '\'' {
                if chars[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                out.push(' ');
                i += 1;
            }
            out.push('\'');
            i += 1;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn prev(chars: &[char], i: usize) -> char {
    if i == 0 { ' ' } else { chars[i - 1] }
}

fn ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// `'x'` or `'\n'` rather than a lifetime `'a`.
fn is_char_literal(chars: &[char], i: usize) -> bool {
    match chars.get(i + 1) {
        Some('\\') => true,
        Some(_) => chars.get(i + 2) == Some(&'\''),
        None => false,
    }
}

/// The code without `#[cfg(test)]` modules (blanked, lines kept).
fn strip_tests(code: &str) -> String {
    let mut out: Vec<char> = code.chars().collect();
    let text: String = out.iter().collect();
    let mut search = 0;
    while let Some(found) = text[search..].find("#[cfg(test)]") {
        let start = search + found;
        let after = start + "#[cfg(test)]".len();
        let mut rest = text[after..].trim_start();
        // `pub mod tests`, `pub(crate) mod tests`: the item after its visibility.
        if let Some(r) = rest.strip_prefix("pub") {
            let r = r.trim_start();
            rest = match r.strip_prefix('(') {
                Some(inner) => inner
                    .split_once(')')
                    .map_or(r, |(_, after)| after.trim_start()),
                None => r,
            };
        }
        let item_start = text.len() - rest.len();
        let end = if rest.starts_with("mod ") {
            match text[item_start..].find('{') {
                Some(open) => matching_brace(&text, item_start + open),
                None => text[item_start..].find(';').map(|e| item_start + e + 1),
            }
        } else if rest.starts_with("use ") {
            text[item_start..].find(';').map(|e| item_start + e + 1)
        } else {
            None
        };
        let Some(end) = end else {
            search = after;
            continue;
        };
        // Byte offsets equal char offsets only for ASCII: blank by chars.
        let (cs, ce) = (text[..start].chars().count(), text[..end].chars().count());
        for c in &mut out[cs..ce] {
            if *c != '\n' {
                *c = ' ';
            }
        }
        search = end;
    }
    out.into_iter().collect()
}

fn matching_brace(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0;
    for (i, c) in text[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + i + 1);
                }
            }
            _ => {}
        }
    }
    None
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].matches('\n').count() + 1
}

/// Words of the code with their byte offsets (identifiers, `::`, braces,
/// commas, `;`, `*`).
fn tokens(code: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut chars = code.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        if ident_char(c) {
            let mut word = c.to_string();
            while let Some(&(_, d)) = chars.peek() {
                if !ident_char(d) {
                    break;
                }
                word.push(d);
                chars.next();
            }
            out.push((i, word));
        } else if c == ':' && chars.peek().is_some_and(|&(_, d)| d == ':') {
            chars.next();
            out.push((i, "::".into()));
        } else if !c.is_whitespace() {
            out.push((i, c.to_string()));
        }
    }
    out
}

/// Names of the modules a file declares with `mod name;` or `mod name {`.
fn declared_modules(code: &str) -> BTreeSet<String> {
    let t = tokens(code);
    t.windows(2)
        .filter(|w| w[0].1 == "mod")
        .map(|w| w[1].1.clone())
        .collect()
}

/// `(line, is pub, tree tokens)` of every `use` statement.
fn use_statements(code: &str) -> Vec<(usize, bool, Vec<String>)> {
    let t = tokens(code);
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        if t[i].1 == "use"
            && (i == 0 || matches!(t[i - 1].1.as_str(), ";" | "}" | "{" | ")" | "]" | "pub"))
        {
            let public = i > 0 && (t[i - 1].1 == "pub" || t[i - 1].1 == ")");
            let line = line_of(code, t[i].0);
            let mut j = i + 1;
            let mut tree = Vec::new();
            while j < t.len() && t[j].1 != ";" {
                tree.push(t[j].1.clone());
                j += 1;
            }
            out.push((line, public, tree));
            i = j;
        }
        i += 1;
    }
    out
}

/// The code with its `use` statements blanked.
fn blank_use_statements(code: &str) -> String {
    let t = tokens(code);
    let mut out: Vec<u8> = code.as_bytes().to_vec();
    let mut i = 0;
    while i < t.len() {
        if t[i].1 == "use" {
            let start = t[i].0;
            let mut j = i;
            while j < t.len() && t[j].1 != ";" {
                j += 1;
            }
            let end = t.get(j).map(|x| x.0).unwrap_or(code.len());
            for b in &mut out[start..end] {
                if *b != b'\n' {
                    *b = b' ';
                }
            }
            i = j;
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The paths a use tree names: `a::{b, c::d as e}` → `a::b`, `a::c::d`
/// (a rename binds the last segment's item under another name; the item's
/// module is what matters here).
fn expand_use_tree(tree: &[String]) -> Vec<Vec<String>> {
    fn walk(tree: &[String], prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
        let mut path = prefix.clone();
        let mut i = 0;
        while i < tree.len() {
            match tree[i].as_str() {
                "::" => {}
                "{" => {
                    let mut depth = 0;
                    let mut start = i + 1;
                    for j in i..tree.len() {
                        match tree[j].as_str() {
                            "{" => depth += 1,
                            "}" => {
                                depth -= 1;
                                if depth == 0 {
                                    walk(&tree[start..j], path.clone(), out);
                                    return;
                                }
                            }
                            "," if depth == 1 => {
                                walk(&tree[start..j], path.clone(), out);
                                start = j + 1;
                            }
                            _ => {}
                        }
                    }
                    return;
                }
                "as" => break,
                "self" if i > 0 => {}
                word => path.push(word.to_string()),
            }
            i += 1;
        }
        if path.len() > prefix.len() || !path.is_empty() {
            out.push(path);
        }
    }
    let mut out = Vec::new();
    walk(tree, Vec::new(), &mut out);
    out
}

/// `(line, segments)` of every path `a::b…` in the code (the longest run of
/// identifiers joined by `::`, not preceded by `::`).
fn qualified_paths(code: &str) -> Vec<(usize, Vec<String>)> {
    let t = tokens(code);
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let starts = ident_char(t[i].1.chars().next().unwrap_or(' '))
            && t.get(i + 1).is_some_and(|x| x.1 == "::")
            && (i == 0 || t[i - 1].1 != "::");
        if starts {
            let line = line_of(code, t[i].0);
            let mut path = vec![t[i].1.clone()];
            let mut j = i + 1;
            while j + 1 < t.len()
                && t[j].1 == "::"
                && ident_char(t[j + 1].1.chars().next().unwrap_or(' '))
            {
                path.push(t[j + 1].1.clone());
                j += 2;
            }
            out.push((line, path));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// Crate roots re-export no module's items: imports name the module that
/// defines what they use (`sfp_renderer::scene::Scene`), so a file's `use`
/// lines show the layers it reaches. Core's vocabulary types, which every
/// crate uses, are the one exception.
#[test]
fn crate_roots_re_export_only_the_vocabulary() {
    const ALLOWED: [&str; 2] = [
        "core: pub use error::{Error, Result};",
        "core: pub use image::{Image, Mask, NormalMap};",
    ];
    let mut found = Vec::new();
    for krate in CRATES {
        let lib = workspace().join(krate).join("src").join("lib.rs");
        let Ok(text) = std::fs::read_to_string(&lib) else {
            continue;
        };
        for line in text
            .lines()
            .filter(|l| l.trim_start().starts_with("pub use "))
        {
            let entry = format!("{krate}: {}", line.trim());
            if !ALLOWED.contains(&entry.as_str()) {
                found.push(entry);
            }
        }
    }
    assert!(found.is_empty(), "crate-root aliases: {found:?}");
}
