//! Scene files that must be refused, each with the exact message it must
//! give.
//!
//! Every `tests/bad_scenes/NAME.toml` is parsed as if it were at that path
//! and its error, printed in full, is compared with `NAME.expected`. A file
//! without an `.expected`, or whose message differs, fails with the actual
//! text, so a changed message is updated on purpose, never by accident.

use std::path::{Path, PathBuf};

use whitted::scene::parse_scene;

/// The bad scene files, sorted by name.
fn bad_scenes() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// What is wrong with the message of `file`, if anything.
fn check(file: &Path) -> Option<String> {
    let name = file.file_name().unwrap().to_str().unwrap();
    let source = std::fs::read_to_string(file).unwrap();
    let shown_path = format!("tests/bad_scenes/{name}");
    let actual = match parse_scene(&source, Path::new(&shown_path)) {
        Ok(_) => return Some(format!("{shown_path} was accepted; it must be refused")),
        Err(error) => error.to_string(),
    };
    let expected_file = file.with_extension("expected");
    let expected = match std::fs::read_to_string(&expected_file) {
        Ok(text) => text,
        Err(_) => {
            return Some(format!(
                "{shown_path} has no {}; its message is:\n{actual}",
                expected_file.file_name().unwrap().to_str().unwrap()
            ));
        }
    };
    let expected = expected.strip_suffix('\n').unwrap_or(&expected);
    (actual != expected).then(|| {
        format!(
            "{shown_path} gives a different message.\n--- expected:\n{expected}\n--- actual:\n{actual}"
        )
    })
}

#[test]
fn every_bad_scene_is_refused_with_its_expected_message() {
    let files = bad_scenes();
    assert!(!files.is_empty(), "no bad scenes found");
    let failures: Vec<String> = files.iter().filter_map(|file| check(file)).collect();
    assert!(
        failures.is_empty(),
        "{} of {} bad scenes failed:\n\n{}",
        failures.len(),
        files.len(),
        failures.join("\n\n")
    );
}

#[test]
fn every_expected_message_has_its_scene() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_scenes");
    let orphans: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "expected"))
        .filter(|path| !path.with_extension("toml").exists())
        .collect();
    assert!(
        orphans.is_empty(),
        "expected files without a scene: {orphans:?}"
    );
}
