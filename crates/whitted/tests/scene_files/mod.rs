//! The scene files the whole-scene tests walk through: the example scenes
//! in the repository and, for the ignored tests, the SPD scenes in the
//! shared folder.

// Each test crate uses some of them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The files in `folder` whose extension is `extension`, sorted.
pub fn files(folder: &Path, extension: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort();
    files
}

/// The example scenes (`scenes/*.toml`), sorted; at least ten.
pub fn example_scenes() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let scenes = files(&folder, "toml");
    assert!(scenes.len() >= 10, "too few scenes in {}", folder.display());
    scenes
}
