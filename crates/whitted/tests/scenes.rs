//! Every example scene in `scenes/` is read and renders to a picture: small,
//! so that the suite stays fast.

use std::path::{Path, PathBuf};

use whitted::integrator::RayKind;
use whitted::render::render;
use whitted::scene::load_scene;

/// The example scenes, sorted by name.
fn example_scenes() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 5, "too few scenes in {}", folder.display());
    scenes
}

#[test]
fn every_example_scene_renders_a_finite_picture_that_is_not_all_background() {
    let (width, height) = (32, 24);
    let mut failures = Vec::new();
    for path in example_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut scene = match load_scene(&path) {
            Ok(loaded) => loaded,
            Err(error) => {
                failures.push(error.to_string());
                continue;
            }
        };
        scene.settings.width = width;
        scene.settings.height = height;
        let spp = u64::from(scene.settings.samples_per_pixel);
        let output = match render(&scene, &|_| {}) {
            Ok(output) => output,
            Err(error) => {
                failures.push(format!("{name}: {error}"));
                continue;
            }
        };
        let film = &output.image;
        assert_eq!(
            (film.width(), film.height(), film.channels()),
            (width, height, 3)
        );
        if let Some(bad) = film.data().iter().find(|v| !v.is_finite() || **v < 0.0) {
            failures.push(format!("{name}: a pixel value of {bad}"));
        }
        let background = scene.background.to_array().map(|c| c as f32);
        let differs = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let p = film.pixel(x, y);
                (0..3).any(|c| (p[c] - background[c]).abs() > 1e-3)
            })
            .count();
        // The objects of every example fill at least a quarter of its frame.
        if differs < (width * height / 4) as usize {
            failures.push(format!(
                "{name}: only {differs} of {} pixels differ from the background",
                width * height
            ));
        }
        let rays = output.rays;
        if rays[RayKind::Primary] != u64::from(width * height) * spp {
            failures.push(format!("{name}: {} primary rays", rays[RayKind::Primary]));
        }
        if !scene.lights.is_empty() && rays[RayKind::Shadow] == 0 {
            failures.push(format!("{name}: lit, yet no shadow ray was traced"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}
