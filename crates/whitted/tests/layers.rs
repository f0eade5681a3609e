//! The library's layers import downwards only: each top-level module may
//! name (`crate::x`) only modules of its own layer or of the layers before
//! it. ARCHITECTURE.md draws the same list and says why.
//!
//! Test code is exempt (a test may build its inputs with anything): the
//! `#[cfg(test)]` module at the end of a file, and files that are only test
//! helpers. Comments are skipped, so a doc link may point upwards to say
//! who uses a type.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The layers, lowest first; a module may import from its own layer and
/// the ones before it. `accel` is apart: it knows `math` only.
const LAYERS: &[&[&str]] = &[
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

/// The file's code without comments and without its trailing test module.
fn code_of(text: &str) -> String {
    let end = text.find("#[cfg(test)]\nmod tests").unwrap_or(text.len());
    text[..end]
        .lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every top-level module named as `crate::name` in `code`.
fn named_modules(code: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find("crate::") {
        rest = &rest[at + "crate::".len()..];
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        names.push(name);
    }
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
        let file_name = relative.file_name().unwrap().to_str().unwrap();
        if relative == Path::new("lib.rs") || TEST_FILES.contains(&file_name) {
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
        for target in named_modules(&code) {
            if target == module || target.is_empty() {
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
fn the_check_sees_an_upward_import_and_ignores_comments_and_tests() {
    let code = code_of(
        "use crate::math::Vec3;\n/// See [`crate::render`].\nfn f() { crate::scene::load(); }\n\
         #[cfg(test)]\nmod tests {\n    use crate::bench::x;\n}\n",
    );
    assert_eq!(named_modules(&code), ["math", "scene"]);
}
