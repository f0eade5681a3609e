//! The library's layers import downwards only: each top-level module may
//! name (`crate::x`) only modules of its own layer or of the layers before
//! it. ARCHITECTURE.md draws the same list and says why.
//!
//! One more rule is checked on the same code: files are read only through
//! `limits` (regular files, bounded by the memory budget), so that no
//! reader can eat memory from a `/dev/zero` or a huge file.
//!
//! Test code is exempt (a test may build its inputs with anything): the
//! `#[cfg(test)]` module at the end of a file, and files that are only test
//! helpers. Plain comments are skipped; doc links are checked like code.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The layers, lowest first; a module may import from its own layer and
/// the ones before it. `accel` is apart: it knows `math` only.
const LAYERS: &[&[&str]] = &[
    &["limits"],
    &["math"],
    &["shape"],
    &["mesh"],
    &["accel"],
    &["world"],
    &["shading"],
    &["integrator"],
    &["image"],
    &["render"],
    &["scene"],
    &["bench"],
];

/// Modules allowed to import only from these, whatever their layer.
const ONLY: &[(&str, &[&str])] = &[("accel", &["math"])];

/// Files that hold only test code.
const TEST_FILES: &[&str] = &["testing.rs", "tests.rs", "conformance.rs"];

/// Whether `relative` holds only test code: one of [`TEST_FILES`], or a
/// file in a folder named `tests` (a test module with files of its own,
/// as `layer-cycles.py` counts them too).
fn is_test_file(relative: &Path) -> bool {
    let name = relative.file_name().and_then(|n| n.to_str()).unwrap_or("");
    TEST_FILES.contains(&name) || relative.components().any(|c| c.as_os_str() == "tests")
}

fn source_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(folder: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The file's code and doc comments, without plain comments and without
/// its inline test module (`#[cfg(test)] mod tests { ... }`, at the end of
/// a file). Doc links count: one pointing up a layer would make a cycle
/// for `layer-cycles.py`, which reads them too.
fn code_of(text: &str) -> String {
    let end = text.find("#[cfg(test)]\nmod tests {").unwrap_or(text.len());
    text[..end]
        .lines()
        .filter(|line| {
            let line = line.trim_start();
            !line.starts_with("//") || line.starts_with("///") || line.starts_with("//!")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// How deep the module of `relative` (a path under `src/`) sits below the
/// crate root: `lib.rs` 0, `world/mod.rs` 1, `world/entry.rs` 2.
fn module_depth(relative: &Path) -> usize {
    let parts = relative.components().count();
    if relative
        .file_name()
        .is_some_and(|f| f == "mod.rs" || f == "lib.rs")
    {
        parts - 1
    } else {
        parts
    }
}

/// The identifier at the start of `text`.
fn identifier(text: &str) -> String {
    text.chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect()
}

/// The first path segment of each item of the `{...}` group `text` starts
/// with (`{a::X, b::{Y, Z}}` gives `a` and `b`).
fn group_heads(text: &str) -> Vec<String> {
    let mut heads = Vec::new();
    let mut depth = 0;
    let mut at_item = true;
    for (i, c) in text.char_indices() {
        match c {
            '{' => {
                depth += 1;
                at_item = depth == 1;
            }
            '}' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            ',' if depth == 1 => at_item = true,
            c if at_item && !c.is_whitespace() => {
                heads.push(identifier(&text[i..]));
                at_item = false;
            }
            _ => {}
        }
    }
    heads
}

/// The top-level modules named at the start of `rest` (just past a path
/// that leads to the crate root): one identifier, or the heads of a group.
fn heads_at(rest: &str) -> Vec<String> {
    let rest = rest.trim_start();
    if rest.starts_with('{') {
        group_heads(rest)
    } else {
        vec![identifier(rest)]
    }
}

/// Every top-level module that `code`, the code of a module `depth` levels
/// below the crate root, names: through `crate::`, and through as many
/// `super::` as lead to the root.
fn named_modules(code: &str, depth: usize) -> Vec<String> {
    let compact: String = code.split_whitespace().collect::<Vec<_>>().join(" ");
    let compact = compact.replace(" ::", "::").replace(":: ", "::");
    let mut names = Vec::new();
    let bytes = compact.as_bytes();
    let mut i = 0;
    while i < compact.len() {
        let starts_word = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        let rest = &compact[i..];
        if starts_word && rest.starts_with("crate::") {
            names.extend(heads_at(&rest["crate::".len()..]));
            i += "crate::".len();
            continue;
        }
        if starts_word && rest.starts_with("super::") {
            let mut k = 0;
            let mut tail = rest;
            while let Some(next) = tail.strip_prefix("super::") {
                k += 1;
                tail = next;
            }
            if k == depth {
                names.extend(heads_at(tail));
            }
            i += k * "super::".len();
            continue;
        }
        i += rest.chars().next().map_or(1, char::len_utf8);
    }
    names.retain(|n| !n.is_empty() && n != "self");
    names
}

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|layer| layer.contains(&module))
}

/// Every import that goes against the layers, as `file: from -> to`.
fn violations() -> Vec<String> {
    let src = source_folder();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut found = Vec::new();
    for file in files {
        let relative = file.strip_prefix(&src).unwrap();
        if relative == Path::new("lib.rs") || is_test_file(relative) {
            continue;
        }
        let first = relative.components().next().unwrap();
        let module = first.as_os_str().to_str().unwrap().trim_end_matches(".rs");
        let Some(mine) = layer_of(module) else {
            found.push(format!(
                "{}: module `{module}` is in no layer",
                relative.display()
            ));
            continue;
        };
        let only = ONLY.iter().find(|(m, _)| *m == module).map(|(_, o)| *o);
        let code = code_of(&std::fs::read_to_string(&file).unwrap());
        for target in named_modules(&code, module_depth(relative)) {
            if target == module {
                continue;
            }
            let allowed = match (only, layer_of(&target)) {
                (Some(only), _) => only.contains(&target.as_str()),
                (None, Some(theirs)) => theirs <= mine,
                (None, None) => false,
            };
            if !allowed {
                found.push(format!("{}: {module} -> {target}", relative.display()));
            }
        }
    }
    found.sort();
    found.dedup();
    found
}

#[test]
fn every_module_imports_only_from_its_layer_or_the_ones_below() {
    let found = violations();
    assert!(
        found.is_empty(),
        "imports against the layers (see ARCHITECTURE.md):\n{}",
        found.join("\n")
    );
}

/// Calls that read a file's contents; outside `limits/` the library reads
/// through `limits::read_input` and `limits::read_input_text` instead.
const UNBOUNDED_READS: &[&str] = &[
    "fs::read(",
    "fs::read_to_string(",
    "File::open(",
    "OpenOptions::new()",
    ".read_to_end(",
    ".read_to_string(",
];

/// Every unbounded read outside `limits/`, as `file: call`.
fn unbounded_reads() -> Vec<String> {
    let root = source_folder();
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut found = Vec::new();
    for file in files {
        let relative = file.strip_prefix(&root).unwrap();
        if relative.starts_with("limits") || is_test_file(relative) {
            continue;
        }
        let code = code_of(&std::fs::read_to_string(&file).unwrap());
        for call in UNBOUNDED_READS {
            if code.contains(call) {
                found.push(format!("{}: {call}", relative.display()));
            }
        }
    }
    found
}

#[test]
fn files_are_read_only_through_limits() {
    let found = unbounded_reads();
    assert!(
        found.is_empty(),
        "files read without the limits of `limits::read_input`:\n{}",
        found.join("\n")
    );
}

#[test]
fn every_top_level_module_has_a_layer() {
    let mut modules = BTreeMap::new();
    for entry in std::fs::read_dir(source_folder()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name != "lib.rs" {
            let module = name.trim_end_matches(".rs").to_string();
            modules.insert(module.clone(), layer_of(&module));
        }
    }
    let missing: Vec<_> = modules.iter().filter(|(_, l)| l.is_none()).collect();
    assert!(missing.is_empty(), "modules in no layer: {missing:?}");
    assert_eq!(modules.len(), LAYERS.iter().map(|l| l.len()).sum::<usize>());
}

#[test]
fn the_check_sees_imports_and_doc_links_and_ignores_comments_and_tests() {
    let code = code_of(
        "use crate::math::Vec3;\n// See crate::image.\n/// See [`crate::render`].\n\
         fn f() { crate::scene::load(); }\n#[cfg(test)]\nmod tests {\n    use crate::bench::x;\n}\n",
    );
    assert_eq!(named_modules(&code, 1), ["math", "render", "scene"]);
}

#[test]
fn the_check_sees_grouped_imports_and_paths_through_super() {
    let code = "use crate::{render::Scene, shading::{Color, Light}};\n\
                use super::super::integrator::Whitted;\n\
                use super::entry::Entry;\n\
                fn f() { crate :: image::Film::new(); }\n";
    // Two levels down, `super::super` is the crate root and `super` is not;
    // one level down, `super` is.
    assert_eq!(
        named_modules(code, 2),
        ["render", "shading", "integrator", "image"]
    );
    assert_eq!(
        named_modules(code, 1),
        ["render", "shading", "entry", "image"]
    );
}

#[test]
fn a_test_module_declared_in_another_file_does_not_hide_the_code_after_it() {
    let code = code_of("#[cfg(test)]\nmod tests;\n\nuse crate::render::Scene;\n");
    assert_eq!(named_modules(&code, 1), ["render"]);
}

#[test]
fn module_depth_counts_from_the_crate_root() {
    assert_eq!(module_depth(Path::new("lib.rs")), 0);
    assert_eq!(module_depth(Path::new("world/mod.rs")), 1);
    assert_eq!(module_depth(Path::new("math.rs")), 1);
    assert_eq!(module_depth(Path::new("world/entry.rs")), 2);
    assert_eq!(module_depth(Path::new("accel/kdtree/mod.rs")), 2);
}
