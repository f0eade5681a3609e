//! OBJ models read from `tests/obj/` and, when present, the shared kitchen.

use std::path::{Path, PathBuf};

use whitted::math::{Ray, Vec3};
use whitted::scene::{LoadedScene, Scene, load_obj};
use whitted::shape::RayShear;
use whitted::texture::Texture;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/obj")
        .join(name)
}

fn load(name: &str) -> LoadedScene {
    load_obj(&fixture(name)).unwrap()
}

/// Whether a ray straight down -z through `(x, y)` hits any mesh.
fn hits(scene: &Scene, x: f64, y: f64) -> bool {
    let ray = Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
    let shear = RayShear::new(&ray);
    scene
        .meshes
        .iter()
        .any(|m| (0..m.len() as u32).any(|i| m.intersect(i, &ray, &shear).is_some()))
}

#[test]
fn every_face_form_and_relative_indices_are_read() {
    let loaded = load("face_forms.obj");
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = loaded.scene;
    // No material, "red paint" (twice), "blue": three meshes.
    assert_eq!(scene.meshes.len(), 3);
    assert_eq!(scene.primitive_count(), 8);
    let red = &scene.materials[scene.mesh_instances[1].material.0 as usize];
    assert_eq!(red.diffuse, Texture::Constant(Vec3::new(1.0, 0.0, 0.0)));
    assert!(red.specular.is_black());
    let blue = &scene.materials[scene.mesh_instances[2].material.0 as usize];
    assert_eq!(blue.reflection, Texture::Constant(Vec3::splat(0.5)));
    // `f 1/1 ...` and `f -4/-4/-1 ...` give different vertices (one has a normal).
    assert_eq!(scene.meshes[1].positions().len(), 8);
    assert_eq!(scene.meshes[2].positions().len(), 4);
}

#[test]
fn a_concave_polygon_leaves_its_notch_empty() {
    let scene = load("concave.obj").scene;
    assert_eq!(scene.primitive_count(), 4);
    assert!(!hits(&scene, 1.5, 1.5), "the notch of the L was hit");
    for (x, y) in [(0.5, 0.5), (1.5, 0.5), (0.5, 1.5)] {
        assert!(hits(&scene, x, y), "({x}, {y}) is inside the L");
    }
}

#[test]
fn smoothing_groups_share_vertices_and_s_off_is_flat() {
    let scene = load("smoothing.obj").scene;
    let mesh = &scene.meshes[0];
    // 6 shared vertices for the smoothed roof, 4 + 4 for the flat one.
    assert_eq!(mesh.positions().len(), 14);
    assert_eq!(mesh.len(), 8);
}

#[test]
fn missing_libraries_and_materials_are_warnings_with_a_grey_fallback() {
    let loaded = load("missing_materials.obj");
    let text: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(text.len(), 2, "{text:?}");
    assert!(
        text[0].contains("missing_materials.obj:1:8: warning: cannot read the material library")
    );
    assert!(text[1].contains("missing_materials.obj:5:8: warning: no material `nowhere`"));
    assert_eq!(
        loaded.scene.materials,
        vec![whitted::material::Material::default()]
    );
}

#[test]
fn the_kitchen_loads_with_its_33_materials() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/models/kitchen/kitchen.obj");
    if !path.exists() {
        eprintln!("skipped: {} is absent", path.display());
        return;
    }
    let loaded = load_obj(&path).unwrap();
    assert_eq!(loaded.scene.materials.len(), 33);
    assert_eq!(loaded.scene.meshes.len(), 33);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
}
