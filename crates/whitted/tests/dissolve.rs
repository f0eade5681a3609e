//! Known-answer renders of dissolved surfaces: a surface of opacity `α`
//! shows `α` of itself and `1 - α` of what is behind it, and lets `1 - α` of
//! the light through to what it shadows.

use std::sync::Arc;

use whitted::math::{DVec2, Transform, Vec3};
use whitted::render::Scene;
use whitted::shading::Color;
use whitted::shading::Material;
use whitted::shading::Texture;
use whitted::shading::texture::{DissolveMap, ImageData, ImageTexture, Wrap};
use whitted::shading::{Attenuation, Light};
use whitted::shape::{Parallelogram, Plane, Shape, Sphere};

mod common;
use common::{add_white_floor, black, pixel, rendered, scene_looking_down_z};

/// A white floor at z = 0 lit by a point light off the axis, with a
/// sphere of `material` between them and the camera.
fn floor_and_sphere(material: Option<Material>) -> Scene {
    let mut scene = scene_looking_down_z(16, 16, 60.0);
    scene.ambient = Color::splat(0.1);
    add_white_floor(&mut scene);
    if let Some(material) = material {
        let m = scene.add_material(material);
        scene.add_primitive(
            Shape::Sphere(Sphere::new(Vec3::new(0.3, 0.2, 1.5), 1.0).unwrap()),
            m,
            Transform::IDENTITY,
        );
    }
    scene.lights.push(Light::Point {
        position: Vec3::new(2.0, 3.0, 6.0),
        intensity: Color::ONE,
        attenuation: Attenuation::NONE,
    });
    scene
}

/// A shiny, mirroring, glowing red surface of opacity `opacity`.
fn shiny_red(opacity: Texture) -> Material {
    Material {
        ambient: Color::new(0.5, 0.0, 0.0).into(),
        diffuse: Color::new(0.8, 0.1, 0.1).into(),
        specular: Color::splat(0.5).into(),
        reflection: Color::splat(0.3).into(),
        emission: Color::new(0.1, 0.0, 0.0).into(),
        opacity,
        ..Material::default()
    }
}

/// A dissolve map of `texels` (one row, left to right), clamped at its
/// edges.
fn dissolve_map(texels: &[f32], filter: Option<Color>) -> Texture {
    let data = ImageData::new(texels.len(), 1, texels.iter().map(|&t| [t; 3]).collect()).unwrap();
    Texture::Dissolve(DissolveMap {
        opacity: ImageTexture {
            wrap: Wrap::Clamp,
            ..ImageTexture::new(Arc::new(data))
        },
        dissolve: 1.0,
        filter,
    })
}

#[test]
fn a_fully_dissolved_surface_is_invisible_and_casts_no_shadow() {
    let without = rendered(&floor_and_sphere(None));
    let clear = rendered(&floor_and_sphere(Some(shiny_red(Color::ZERO.into()))));
    let opaque = rendered(&floor_and_sphere(Some(shiny_red(Color::ONE.into()))));
    let mut hidden = 0;
    for y in 0..16 {
        for x in 0..16 {
            let (a, b) = (pixel(&without, x, y), pixel(&clear, x, y));
            assert!(
                (a - b).abs().max_element() < 1e-6,
                "({x}, {y}): {a} without the sphere, {b} with a clear one"
            );
            hidden += usize::from(pixel(&opaque, x, y) != a);
        }
    }
    // The opaque sphere covers part of the picture and shadows the floor.
    assert!(hidden > 20, "{hidden}");
}

#[test]
fn an_opaque_dissolve_map_changes_nothing() {
    let constant = rendered(&floor_and_sphere(Some(shiny_red(Color::ONE.into()))));
    let map = rendered(&floor_and_sphere(Some(shiny_red(dissolve_map(
        &[1.0, 1.0],
        None,
    )))));
    assert_eq!(constant, map);
}

#[test]
fn half_opacity_shows_half_the_surface_and_half_what_is_behind() {
    let mut scene = scene_looking_down_z(16, 16, 60.0);
    let back = scene.add_material(Material {
        emission: Color::new(0.0, 0.2, 1.0).into(),
        ..black()
    });
    let front = scene.add_material(Material {
        emission: Color::new(1.0, 0.6, 0.0).into(),
        reflection: Color::splat(0.5).into(),
        opacity: Color::splat(0.5).into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        back,
        Transform::IDENTITY,
    );
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::new(0.0, 0.0, 1.0), Vec3::Z).unwrap()),
        front,
        Transform::IDENTITY,
    );
    // The mirror sees the black sky: it only darkens the surface's half.
    let film = rendered(&scene);
    let expected = 0.5 * Color::new(1.0, 0.6, 0.0) + 0.5 * Color::new(0.0, 0.2, 1.0);
    for (x, y) in [(0, 0), (7, 8), (15, 3)] {
        let c = pixel(&film, x, y);
        assert!(
            (c - expected).abs().max_element() < 1e-7,
            "({x}, {y}): {c}, expected {expected}"
        );
    }
}

#[test]
fn light_passes_a_cut_out_where_its_dissolve_map_is_clear() {
    let mut scene = scene_looking_down_z(16, 16, 60.0);
    let floor = scene.add_material(Material {
        diffuse: Color::ONE.into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        floor,
        Transform::IDENTITY,
    );
    // Behind the camera, between the light and the floor: clear for
    // u < 3/8 (x < -1), opaque for u > 5/8 (x > 1).
    let leaf = scene.add_material(Material {
        diffuse: Color::new(0.0, 1.0, 0.0).into(),
        opacity: dissolve_map(&[0.0, 0.0, 1.0, 1.0], None),
        ..Material::default()
    });
    scene.add_primitive(
        Shape::Parallelogram(
            Parallelogram::new(
                Vec3::new(-4.0, -4.0, 7.0),
                Vec3::new(8.0, 0.0, 0.0),
                Vec3::new(0.0, 8.0, 0.0),
            )
            .unwrap(),
        ),
        leaf,
        Transform::IDENTITY,
    );
    scene.lights.push(Light::Directional {
        direction: -Vec3::Z,
        intensity: Color::ONE,
    });
    let film = rendered(&scene);
    // Looking down -z with y up, -x is on the left of the picture.
    for y in [2, 8, 13] {
        assert_eq!(pixel(&film, 0, y), Color::ONE, "lit through the clear part");
        assert_eq!(
            pixel(&film, 15, y),
            Color::ZERO,
            "shadowed by the opaque part"
        );
    }
}

#[test]
fn mtl_glass_lets_its_filter_through_where_its_dissolve_map_is_clear() {
    let material = Material {
        transmission: dissolve_map(&[0.0, 1.0], Some(Color::new(1.0, 0.5, 0.25))),
        ..black()
    };
    assert_eq!(
        material.pass_through(DVec2::new(0.1, 0.5)),
        Color::new(1.0, 0.5, 0.25)
    );
    assert_eq!(material.pass_through(DVec2::new(0.9, 0.5)), Color::ZERO);
}
