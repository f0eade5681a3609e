//! OBJ models read from `tests/obj/` and the shared kitchen (ignored by
//! default: it needs the shared folder; run with `cargo test -- --ignored`).

mod shared_folder;

use std::path::{Path, PathBuf};

use whitted::math::{Ray, Vec3};
use whitted::render::Camera;
use whitted::render::Scene;
use whitted::render::render;
use whitted::scene::obj::headlight;
use whitted::scene::{LoadedScene, load_obj};
use whitted::shading::Color;
use whitted::shading::Texture;
use whitted::shape::RayShear;

use shared_folder::shared_path;

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
        .objects
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
    assert_eq!(scene.objects.meshes.len(), 3);
    assert_eq!(scene.objects.primitive_count(), 8);
    let red = &scene.materials[scene.objects.mesh_instances[1].material.0 as usize];
    assert_eq!(red.diffuse, Texture::Constant(Color::RED));
    assert!(red.specular.is_black());
    let blue = &scene.materials[scene.objects.mesh_instances[2].material.0 as usize];
    assert_eq!(blue.reflection, Texture::Constant(Color::splat(0.5)));
    // `f 1/1 ...` and `f -4/-4/-1 ...` give different vertices (one has a normal).
    assert_eq!(scene.objects.meshes[1].positions().len(), 8);
    assert_eq!(scene.objects.meshes[2].positions().len(), 4);
}

#[test]
fn a_concave_polygon_leaves_its_notch_empty() {
    let scene = load("concave.obj").scene;
    assert_eq!(scene.objects.primitive_count(), 4);
    assert!(!hits(&scene, 1.5, 1.5), "the notch of the L was hit");
    for (x, y) in [(0.5, 0.5), (1.5, 0.5), (0.5, 1.5)] {
        assert!(hits(&scene, x, y), "({x}, {y}) is inside the L");
    }
}

#[test]
fn smoothing_groups_share_vertices_and_s_off_is_flat() {
    let scene = load("smoothing.obj").scene;
    let mesh = &scene.objects.meshes[0];
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
        vec![whitted::shading::Material::default()]
    );
}

#[test]
#[ignore = "needs ../shared/scenes/models/kitchen; run with: cargo test -- --ignored"]
fn the_kitchen_loads_with_its_33_materials_and_no_warnings() {
    let path = shared_path("scenes/models/kitchen/kitchen.obj");
    let loaded = load_obj(&path).unwrap();
    assert_eq!(loaded.scene.materials.len(), 33);
    assert_eq!(loaded.scene.objects.meshes.len(), 33);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
}

#[test]
fn map_kd_shows_its_texture_under_a_head_on_light() {
    let loaded = load("textured.obj");
    let warnings: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(
        warnings[0].contains("textured.mtl:11:15: warning: cannot read the image")
            && warnings[0].contains("missing.png`")
            && warnings[0].contains("`Kd` keeps its constant colour"),
        "{}",
        warnings[0]
    );
    assert!(
        warnings[1]
            .contains("textured.mtl:12:1: warning: 1 texture map in this library not applied"),
        "{}",
        warnings[1]
    );
    let mut scene = loaded.scene;
    // Eye 5 units in front of the quad; the 4 x 4 image spans exactly the
    // quad, so pixel centres see (±0.25, ±0.75)-style points.
    let fov = 2.0 * 0.2f64.atan().to_degrees();
    scene.camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, fov).unwrap();
    scene.lights = vec![headlight(&scene.camera)];
    scene.settings.width = 4;
    scene.settings.height = 4;
    let film = render(&scene, &|_| {}).unwrap().image;
    // A corner pixel sees (±0.75, ±0.75, 0): N·L = 5 / |(0.75, 0.75, 5)|.
    let cosine = 5.0 / (25.0f64 + 2.0 * 0.75 * 0.75).sqrt();
    for (x, y, texel) in [
        (0, 0, Color::RED),
        (3, 0, Color::GREEN),
        (0, 3, Color::BLUE),
        (3, 3, Color::ONE),
    ] {
        let p = film.pixel(x, y);
        let got = Color::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
        assert!(
            (got - texel * cosine).abs().max_element() < 1e-5,
            "pixel ({x}, {y}): {got}"
        );
    }
}
