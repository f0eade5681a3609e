//! Helpers shared by the known-answer render tests.

// Each test crate uses some of them.
#![allow(dead_code)]

use whitted::image::Film;
use whitted::math::{Transform, Vec3};
use whitted::render::Camera;
use whitted::render::Scene;
use whitted::render::render;
use whitted::shading::Color;
use whitted::shading::Material;
use whitted::shading::Texture;
use whitted::shape::{Plane, Shape};

/// A material with no ambient and no diffuse colour.
pub fn black() -> Material {
    Material {
        ambient: Texture::default(),
        diffuse: Texture::default(),
        ..Material::default()
    }
}

/// A scene of `width` x `height` pixels seen from z = 5 down -z at the
/// origin, with a vertical field of view of `fov` degrees.
pub fn scene_looking_down_z(width: u32, height: u32, fov: f64) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, fov).unwrap();
    let mut scene = Scene::new(camera);
    scene.settings.width = width;
    scene.settings.height = height;
    scene
}

/// The scene's picture.
pub fn rendered(scene: &Scene) -> Film {
    render(scene, &|_| {}).unwrap().image
}

/// Pixel (x, y) of `film` as a colour.
pub fn pixel(film: &Film, x: u32, y: u32) -> Color {
    let p = film.pixel(x, y);
    Color::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

/// Adds a white floor at z = 0, lit and ambient at full strength.
pub fn add_white_floor(scene: &mut Scene) {
    let floor = scene.add_material(Material {
        diffuse: Color::ONE.into(),
        ambient: Color::ONE.into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        floor,
        Transform::IDENTITY,
    );
}
