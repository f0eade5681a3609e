//! Every example scene in `scenes/` parses.

use std::path::{Path, PathBuf};

use whitted::scene::load_scene;

#[test]
fn every_example_scene_parses() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 3, "too few scenes in {}", folder.display());
    let failures: Vec<String> = scenes
        .iter()
        .filter_map(|path| load_scene(path).err().map(|error| error.to_string()))
        .collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}
