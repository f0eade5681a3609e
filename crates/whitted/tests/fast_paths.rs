//! The fast paths change no picture: every example scene, and (with
//! `--ignored`) every SPD scene, renders to the same bits, with the same
//! camera, reflected and refracted rays, when every ray takes the plain
//! closest-hit or any-hit query instead (`RenderSettings::fast_paths` off:
//! no camera-ray packets or culling, no shadow cache, no classifying walk
//! or crossings for shadow rays through glass, no interior lists for rays
//! inside glass spheres). Shadow rays may be fewer with them: a shadow ray
//! that the classifying walk finds blocked behind a clear surface is one
//! ray, where the surface-to-surface walk casts one more from each clear
//! surface it passes before it reaches the blocker.

mod scene_files;
mod shared_folder;

use std::path::PathBuf;

use whitted::integrator::RayKind;
use whitted::render::{Scene, render};
use whitted::scene::load_any;

use scene_files::{example_scenes, files};
use shared_folder::shared_path;

/// Renders `scene` at `width` x `height` with the fast paths and without,
/// and returns a message for each difference.
fn differences(name: &str, mut scene: Scene, (width, height): (u32, u32)) -> Vec<String> {
    scene.settings.width = width;
    scene.settings.height = height;
    let [fast, reference] = [true, false].map(|fast| {
        scene.settings.fast_paths = fast;
        render(&scene, &|_| {}).unwrap_or_else(|e| panic!("{name}: {e}"))
    });
    let mut found = Vec::new();
    let bits = |data: &[f32]| data.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    if bits(fast.image.data()) != bits(reference.image.data()) {
        found.push(format!("{name}: the pictures differ"));
    }
    for kind in RayKind::ALL {
        let (with, without) = (fast.rays[kind], reference.rays[kind]);
        let same = match kind {
            RayKind::Shadow => with <= without,
            _ => with == without,
        };
        if !same {
            found.push(format!(
                "{name}: {with} {} rays with the fast paths, {without} without",
                kind.name()
            ));
        }
    }
    found
}

/// Every scene of `paths`, rendered both ways; fails with every difference.
fn assert_same_both_ways(paths: &[PathBuf], size: (u32, u32)) {
    let mut found = Vec::new();
    for path in paths {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let scene = load_any(path).unwrap_or_else(|e| panic!("{name}: {e}"));
        found.extend(differences(&name, scene, size));
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

#[test]
fn every_example_scene_renders_the_same_without_the_fast_paths() {
    assert_same_both_ways(&example_scenes(), (64, 48));
}

#[test]
#[ignore = "needs ../shared/scenes/spd (the SPD scenes); run with: cargo test -- --ignored"]
fn every_spd_scene_renders_the_same_without_the_fast_paths() {
    let scenes = files(&shared_path("scenes/spd"), "nff");
    assert_eq!(scenes.len(), 14, "the 14 SPD scenes");
    assert_same_both_ways(&scenes, (96, 96));
}
