//! OBJ files that must be refused, each with the exact message it must give.
//!
//! Every `tests/bad_obj/NAME.obj` is parsed as if it were at that path and
//! its error, printed in full, is compared with `NAME.expected`. A file
//! without an `.expected`, or whose message differs, fails with the actual
//! text, so a changed message is updated on purpose, never by accident.

use std::path::{Path, PathBuf};

use whitted::scene::parse_obj;

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_obj")
}

/// The files of the folder with `extension`, sorted by name.
fn files(extension: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort();
    files
}

/// What is wrong with the message of `file`, if anything.
fn check(file: &Path) -> Option<String> {
    let name = file.file_name().unwrap().to_str().unwrap();
    let source = std::fs::read_to_string(file).unwrap();
    let shown_path = format!("tests/bad_obj/{name}");
    let actual = match parse_obj(&source, Path::new(&shown_path)) {
        Ok(_) => return Some(format!("{shown_path} was accepted; it must be refused")),
        Err(error) => error.to_string(),
    };
    let Ok(expected) = std::fs::read_to_string(file.with_extension("expected")) else {
        return Some(format!(
            "{shown_path} has no .expected; its message is:\n{actual}"
        ));
    };
    let expected = expected.strip_suffix('\n').unwrap_or(&expected);
    (actual != expected).then(|| {
        format!(
            "{shown_path} gives a different message.\n--- expected:\n{expected}\n--- actual:\n{actual}"
        )
    })
}

#[test]
fn every_bad_obj_file_is_refused_with_its_expected_message() {
    let files = files("obj");
    assert!(!files.is_empty(), "no bad OBJ files found");
    let failures: Vec<String> = files.iter().filter_map(|file| check(file)).collect();
    assert!(
        failures.is_empty(),
        "{} of {} bad OBJ files failed:\n\n{}",
        failures.len(),
        files.len(),
        failures.join("\n\n")
    );
}

#[test]
fn every_expected_message_has_its_file() {
    let orphans: Vec<PathBuf> = files("expected")
        .into_iter()
        .filter(|path| !path.with_extension("obj").exists())
        .collect();
    assert!(
        orphans.is_empty(),
        "expected files without an OBJ file: {orphans:?}"
    );
}
