//! Files that must be refused, each with the exact message it must give:
//! `tests/bad_scenes/*.toml` (our format), `tests/bad_nff/*.nff` and
//! `tests/bad_obj/*.obj`.
//!
//! Every `FOLDER/NAME.EXT` is parsed as if it were at that path and its
//! error, printed in full, is compared with `FOLDER/NAME.expected`. A file
//! without an `.expected`, or whose message differs, fails with the actual
//! text, so a changed message is updated on purpose, never by accident.

use std::path::{Path, PathBuf};

use whitted::scene::{SceneError, parse_nff, parse_obj, parse_scene};

/// A reader: the text of a file and the path to show, to the error (or to
/// nothing when the file is accepted).
type Parse = fn(&str, &Path) -> Result<(), SceneError>;

/// The files of `folder` with `extension`, sorted by name.
fn files(folder: &str, extension: &str) -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(folder);
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort();
    files
}

/// What is wrong with the message of `file`, if anything.
fn check(folder: &str, file: &Path, parse: Parse) -> Option<String> {
    let name = file.file_name().unwrap().to_str().unwrap();
    let source = std::fs::read_to_string(file).unwrap();
    let shown_path = format!("tests/{folder}/{name}");
    let actual = match parse(&source, Path::new(&shown_path)) {
        Ok(()) => return Some(format!("{shown_path} was accepted; it must be refused")),
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

/// Every file of `folder` is refused with its expected message, and every
/// `.expected` has its file.
fn assert_folder(folder: &str, extension: &str, parse: Parse) {
    let files = files(folder, extension);
    assert!(!files.is_empty(), "no .{extension} files in tests/{folder}");
    let failures: Vec<String> = files
        .iter()
        .filter_map(|file| check(folder, file, parse))
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} files in tests/{folder} failed:\n\n{}",
        failures.len(),
        files.len(),
        failures.join("\n\n")
    );
    let orphans: Vec<PathBuf> = self::files(folder, "expected")
        .into_iter()
        .filter(|path| !path.with_extension(extension).exists())
        .collect();
    assert!(
        orphans.is_empty(),
        "expected messages without a file: {orphans:?}"
    );
}

#[test]
fn every_bad_scene_file_is_refused_with_its_expected_message() {
    assert_folder("bad_scenes", "toml", |source, path| {
        parse_scene(source, path).map(drop)
    });
}

#[test]
fn every_bad_nff_file_is_refused_with_its_expected_message() {
    assert_folder("bad_nff", "nff", |source, path| {
        parse_nff(source, path).map(drop)
    });
}

#[test]
fn every_bad_obj_file_is_refused_with_its_expected_message() {
    assert_folder("bad_obj", "obj", |source, path| {
        parse_obj(source, path).map(drop)
    });
}
