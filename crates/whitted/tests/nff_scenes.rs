//! NFF files that must be read: the SPD reference scenes (in the shared
//! folder; ignored by default, run with `cargo test -- --ignored`) and a
//! small SPD-like fixture kept in the repository.

mod shared_folder;

use std::path::{Path, PathBuf};

use whitted::math::Vec3;
use whitted::scene::{load_any, load_nff};
use whitted::shading::Color;
use whitted::shading::Light;

use shared_folder::shared_path;

/// The SPD scenes, outside the repository: `shared/scenes/spd` beside it.
fn spd_folder() -> PathBuf {
    shared_path("scenes/spd")
}

#[test]
#[ignore = "needs ../shared/scenes/spd (the SPD scenes); run with: cargo test -- --ignored"]
fn every_spd_scene_parses_into_primitives_and_lights() {
    let folder = spd_folder();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", folder.display()))
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|e| e == "nff"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no .nff files in {}", folder.display());
    let mut failures = Vec::new();
    for file in &files {
        match load_nff(file) {
            Ok(scene) => assert!(
                scene.objects.primitive_count() > 0 && !scene.lights.is_empty(),
                "{} is empty",
                file.display()
            ),
            Err(error) => failures.push(error.to_string()),
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

#[test]
#[ignore = "needs ../shared/scenes/spd (the SPD scenes); run with: cargo test -- --ignored"]
fn the_spd_primitive_counts_are_kept() {
    // Totals from the SPD's own statistics, as listed in its README.
    for (name, total) in [
        ("balls", 7382),
        ("gears", 9345),
        ("teapot", 9264),
        ("tree", 8191),
    ] {
        let file = shared_path(&format!("scenes/spd/{name}.nff"));
        let scene = load_nff(&file).unwrap();
        assert_eq!(scene.objects.primitive_count(), total, "{name}");
    }
}

#[test]
fn the_spd_like_fixture_reads_every_entity() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/nff/spd_like.nff");
    let scene = load_any(&file).unwrap();
    assert_eq!((scene.settings.width, scene.settings.height), (64, 48));
    assert_eq!(scene.background, Color::new(0.078, 0.361, 0.753));
    assert_eq!(scene.camera.eye(), Vec3::new(0.0, -6.0, 2.5));
    let kinds: Vec<&str> = scene
        .objects
        .primitives
        .iter()
        .map(|p| p.shape.kind())
        .collect();
    assert_eq!(
        kinds,
        ["polygon", "sphere", "cone", "cylinder", "sphere", "polygon"]
    );
    // The patch is a smooth mesh.
    assert_eq!(scene.objects.meshes.len(), 1);
    assert_eq!(scene.objects.primitive_count(), 7);
    // Four distinct `f` entities, in order of appearance.
    let materials: Vec<u32> = scene
        .objects
        .primitives
        .iter()
        .map(|p| p.material.0)
        .collect();
    assert_eq!(materials, [0, 1, 1, 1, 2, 3]);
    assert_eq!(scene.objects.mesh_instances[0].material.0, 3);
    assert!(scene.materials[2].is_transmissive());
    let intensities: Vec<Color> = scene
        .lights
        .iter()
        .filter_map(|light| match light {
            Light::Point { intensity, .. } => Some(*intensity),
            _ => None,
        })
        .collect();
    let default = Color::splat(1.0 / 2f64.sqrt());
    assert_eq!(intensities, [default, Color::new(0.3, 0.3, 0.25)]);
}

#[test]
fn an_nff_background_is_written_to_png_as_pov_ray_writes_it() {
    let source = "b 0.078 0.361 0.753\nv\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 30\n\
                  hither 1\nresolution 2 2\n";
    let scene = whitted::scene::parse_nff(source, Path::new("sky.nff")).unwrap();
    let film = whitted::render::render(&scene, &|_| {}).unwrap().image;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sky.png");
    film.write(&path).unwrap();
    let mut reader =
        png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()))
            .read_info()
            .unwrap();
    let mut codes = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut codes).unwrap();
    // POV-Ray 3.7 writes the SPD's POV-Ray export of this background so.
    assert_eq!(&codes[..3], &[20, 92, 192]);
}
