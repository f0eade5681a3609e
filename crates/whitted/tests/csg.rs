//! CSG objects rendered whole, where the answer is known: light through a
//! hollow glass shell is dimmed by `kt` at each of its four surfaces, for
//! camera rays and for shadow rays alike.

use whitted::math::{Transform, Vec3};
use whitted::shading::{Attenuation, Color, Light, Material};
use whitted::shape::{Csg, CsgChild, CsgOperation, Plane, Shape, Sphere};

mod common;
use common::{black, pixel, rendered, scene_looking_down_z};

/// A sphere of radius `outer` around `centre` minus one of radius `inner`.
fn shell(centre: Vec3, outer: f64, inner: f64) -> Shape {
    let sphere = |radius| CsgChild {
        shape: Shape::Sphere(Sphere::new(centre, radius).unwrap()),
        transform: None,
        material: None,
    };
    Shape::Csg(Csg::new(CsgOperation::Difference, vec![sphere(outer), sphere(inner)]).unwrap())
}

fn assert_close(actual: Color, expected: Color) {
    assert!(
        (actual - expected).abs().max_element() <= 1e-6,
        "got {actual:?}, expected {expected:?}"
    );
}

#[test]
fn a_camera_ray_through_the_middle_of_a_glass_shell_is_dimmed_at_four_surfaces() {
    let mut scene = scene_looking_down_z(5, 5, 10.0);
    scene.background = Color::new(1.0, 0.5, 0.25);
    let glass = scene.add_material(Material {
        transmission: Color::splat(0.9).into(),
        ior: 1.5,
        ..black()
    });
    scene.add_primitive(shell(Vec3::ZERO, 1.0, 0.8), glass, Transform::IDENTITY);
    let film = rendered(&scene);
    assert_close(pixel(&film, 2, 2), 0.9f64.powi(4) * scene.background);
}

#[test]
fn a_shadow_through_a_glass_shell_is_dimmed_at_four_surfaces() {
    // As the plain sphere's shadow test in known_answers.rs: a light
    // shining down at 45° through the shell's centre onto the point of
    // the floor the centre pixel sees.
    let mut scene = scene_looking_down_z(5, 5, 10.0);
    let floor = scene.add_material(Material {
        diffuse: Color::ONE.into(),
        ..black()
    });
    let kt = Color::new(0.5, 0.8, 1.0);
    let glass = scene.add_material(Material {
        transmission: kt.into(),
        ior: 1.0,
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        floor,
        Transform::IDENTITY,
    );
    scene.add_primitive(
        shell(Vec3::new(1.0, 0.0, 1.0), 0.5, 0.3),
        glass,
        Transform::IDENTITY,
    );
    scene.lights.push(Light::Point {
        position: Vec3::new(2.0, 0.0, 2.0),
        intensity: Color::ONE,
        attenuation: Attenuation::NONE,
    });
    let film = rendered(&scene);
    let unshadowed = 1.0 / 2f64.sqrt();
    assert_close(pixel(&film, 2, 2), unshadowed * kt * kt * kt * kt);
}
