//! Renders of analytic scenes whose correct pixel values are known exactly.

use whitted::integrator::RayKind;
use whitted::math::{Transform, Vec3};
use whitted::render::Scene;
use whitted::render::render;
use whitted::shading::Color;
use whitted::shading::Material;
use whitted::shading::{Attenuation, Light};
use whitted::shape::{Plane, Shape, Sphere};

mod common;
use common::{black, pixel, rendered, scene_looking_down_z};

fn assert_close(actual: Color, expected: Color, tolerance: f64) {
    assert!(
        (actual - expected).abs().max_element() <= tolerance,
        "got {actual:?}, expected {expected:?}"
    );
}

#[test]
fn diffuse_plane_lit_head_on_is_kd_times_intensity_in_every_pixel() {
    let mut scene = scene_looking_down_z(17, 11, 60.0);
    let kd = Color::new(0.5, 0.25, 0.75);
    let intensity = Color::new(0.8, 1.0, 0.6);
    let material = scene.add_material(Material {
        diffuse: kd.into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        material,
        Transform::IDENTITY,
    );
    scene.lights.push(Light::Directional {
        direction: -Vec3::Z,
        intensity,
    });
    let film = rendered(&scene);
    let expected = (kd * intensity).to_f32();
    for y in 0..11 {
        for x in 0..17 {
            assert_eq!(film.pixel(x, y), expected.as_slice(), "({x}, {y})");
        }
    }
}

#[test]
fn point_light_follows_the_cosine_and_inverse_square_laws() {
    let mut scene = scene_looking_down_z(3, 3, 60.0);
    let material = scene.add_material(Material {
        diffuse: Color::ONE.into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        material,
        Transform::IDENTITY,
    );
    // Light 2 units above the point the centre pixel sees, off to the side
    // by 2: distance √8, cos θ = 2 / √8.
    scene.lights.push(Light::Point {
        position: Vec3::new(2.0, 0.0, 2.0),
        intensity: Color::splat(8.0),
        attenuation: Attenuation {
            constant: 0.0,
            linear: 0.0,
            quadratic: 1.0,
        },
    });
    let film = rendered(&scene);
    let expected = 8.0 / 8.0 * (2.0 / 8f64.sqrt());
    assert_close(pixel(&film, 1, 1), Color::splat(expected), 1e-6);
}

#[test]
fn ambient_and_emission_add_up_without_lights() {
    let mut scene = scene_looking_down_z(5, 5, 40.0);
    scene.ambient = Color::new(0.2, 0.4, 0.6);
    let material = scene.add_material(Material {
        ambient: Color::splat(0.5).into(),
        emission: Color::new(0.1, 0.0, 0.05).into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        material,
        Transform::IDENTITY,
    );
    let film = rendered(&scene);
    assert_close(pixel(&film, 2, 2), Color::new(0.2, 0.2, 0.35), 1e-7);
}

#[test]
fn mirror_facing_a_coloured_wall_shows_the_wall_colour_times_kr() {
    let mut scene = scene_looking_down_z(9, 9, 30.0);
    let kr = Color::new(0.9, 0.5, 0.25);
    let wall_colour = Color::new(0.2, 0.8, 0.6);
    let mirror = scene.add_material(Material {
        reflection: kr.into(),
        ..black()
    });
    let wall = scene.add_material(Material {
        emission: wall_colour.into(),
        ..black()
    });
    scene.background = Color::ONE;
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        mirror,
        Transform::IDENTITY,
    );
    // The wall is behind the camera, facing the mirror.
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::new(0.0, 0.0, 10.0), -Vec3::Z).unwrap()),
        wall,
        Transform::IDENTITY,
    );
    let film = rendered(&scene);
    for y in 0..9 {
        for x in 0..9 {
            assert_close(pixel(&film, x, y), kr * wall_colour, 1e-7);
        }
    }
}

#[test]
fn light_through_the_centre_of_a_glass_sphere_is_scaled_by_kt_twice() {
    let mut scene = scene_looking_down_z(5, 5, 10.0);
    scene.background = Color::new(1.0, 0.5, 0.25);
    let glass = scene.add_material(Material {
        transmission: Color::splat(0.9).into(),
        ior: 1.5,
        ..black()
    });
    scene.add_primitive(
        Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap()),
        glass,
        Transform::IDENTITY,
    );
    let film = rendered(&scene);
    assert_close(pixel(&film, 2, 2), 0.81 * scene.background, 1e-6);
}

#[test]
fn glass_sphere_never_shows_black_from_total_internal_reflection() {
    let mut scene = scene_looking_down_z(41, 41, 30.0);
    scene.background = Color::ONE;
    let glass = scene.add_material(Material {
        transmission: Color::ONE.into(),
        ior: 2.4,
        fresnel: true,
        ..black()
    });
    scene.add_primitive(
        Shape::Sphere(Sphere::new(Vec3::ZERO, 1.5).unwrap()),
        glass,
        Transform::IDENTITY,
    );
    scene.settings.max_depth = 30;
    scene.settings.min_weight = 0.0;
    let film = rendered(&scene);
    for y in 0..41 {
        for x in 0..41 {
            let c = pixel(&film, x, y);
            assert!(c.min_element() > 0.5, "pixel ({x}, {y}) is dark: {c:?}");
        }
    }
}

fn shadow_scene(occluder: Material) -> Scene {
    let mut scene = scene_looking_down_z(5, 5, 10.0);
    let floor = scene.add_material(Material {
        diffuse: Color::ONE.into(),
        ..black()
    });
    let occluder = scene.add_material(occluder);
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        floor,
        Transform::IDENTITY,
    );
    // A small sphere beside the line of sight, between the floor and a
    // light that shines along -z from off-axis.
    scene.add_primitive(
        Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 1.0), 0.5).unwrap()),
        occluder,
        Transform::IDENTITY,
    );
    scene.lights.push(Light::Point {
        position: Vec3::new(2.0, 0.0, 2.0),
        intensity: Color::ONE,
        attenuation: Attenuation::NONE,
    });
    scene
}

#[test]
fn opaque_occluder_blocks_the_light_completely() {
    let film = rendered(&shadow_scene(black()));
    assert_eq!(pixel(&film, 2, 2), Color::ZERO);
}

#[test]
fn transparent_occluder_attenuates_by_kt_at_each_surface() {
    let film = rendered(&shadow_scene(Material {
        transmission: Color::new(0.5, 0.8, 1.0).into(),
        ior: 1.0,
        ..black()
    }));
    let unshadowed = 1.0 / 2f64.sqrt();
    let kt = Color::new(0.5, 0.8, 1.0);
    assert_close(pixel(&film, 2, 2), unshadowed * kt * kt, 1e-6);
}

#[test]
fn phong_highlight_peaks_where_the_mirror_direction_meets_the_eye() {
    let mut scene = scene_looking_down_z(3, 3, 10.0);
    let material = scene.add_material(Material {
        specular: Color::ONE.into(),
        shininess: 10.0,
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        material,
        Transform::IDENTITY,
    );
    scene.lights.push(Light::Directional {
        direction: -Vec3::Z,
        intensity: Color::ONE,
    });
    let film = rendered(&scene);
    assert_close(pixel(&film, 1, 1), Color::ONE, 1e-12);
    let corner = pixel(&film, 0, 0).r;
    assert!(corner < 1.0 && corner > 0.9, "{corner}");
}

#[test]
fn picture_is_identical_whatever_the_thread_count() {
    let mut scene = whitted::scene::default_scene();
    scene.settings.width = 48;
    scene.settings.height = 36;
    scene.settings.samples_per_pixel = 4;
    let with = |threads| {
        let mut scene = scene.clone();
        scene.settings.threads = Some(threads);
        render(&scene, &|_| {}).unwrap()
    };
    let one = with(1);
    let three = with(3);
    assert_eq!(one.image, three.image);
    assert_eq!(one.rays, three.rays);
}

#[test]
fn aovs_give_depth_normal_and_primitive_of_the_centre_ray() {
    use whitted::render::Aov;
    let mut scene = scene_looking_down_z(3, 3, 90.0);
    let material = scene.add_material(Material::default());
    // Every centre ray sees a wall 5 units away (the sphere far behind
    // it is hidden); without the wall, nothing.
    scene.add_primitive(
        Shape::Sphere(Sphere::new(Vec3::new(0.0, 0.0, -1000.0), 1.0).unwrap()),
        material,
        Transform::IDENTITY,
    );
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        material,
        Transform::IDENTITY,
    );
    scene.settings.aovs = vec![Aov::Id, Aov::Depth, Aov::Normal];
    let out = render(&scene, &|_| {}).unwrap();
    let film = |aov| &out.aovs.iter().find(|(a, _)| *a == aov).unwrap().1;
    assert_eq!(out.aovs[0].0, Aov::Id);
    assert_eq!(film(Aov::Depth).pixel(1, 1), &[5.0]);
    assert_eq!(film(Aov::Normal).pixel(1, 1), &[0.0, 0.0, 1.0]);
    assert_eq!(film(Aov::Id).pixel(1, 1), &[1.0]);
    // The corner pixel's centre ray leaves at (1/3, 1/3) of the 45° half
    // field: it meets the plane farther away.
    let corner_depth = f64::from(film(Aov::Depth).pixel(0, 0)[0]);
    let s: f64 = 2.0 / 3.0;
    assert!((corner_depth - 5.0 * (1.0 + 2.0 * s * s).sqrt()).abs() < 1e-5);

    scene.objects.primitives.pop();
    let out = render(&scene, &|_| {}).unwrap();
    let film = |aov| &out.aovs.iter().find(|(a, _)| *a == aov).unwrap().1;
    assert_eq!(film(Aov::Depth).pixel(0, 0), &[f32::INFINITY]);
    assert_eq!(film(Aov::Normal).pixel(0, 0), &[0.0, 0.0, 0.0]);
    assert_eq!(film(Aov::Id).pixel(0, 0), &[-1.0]);
}

#[test]
fn facing_perfect_mirrors_recurse_to_the_deepest_allowed_depth_without_overflow() {
    use whitted::render::{MAX_DEPTH, RenderError};
    let mut scene = scene_looking_down_z(2, 2, 10.0);
    let mirror = scene.add_material(Material {
        reflection: Color::ONE.into(),
        emission: Color::splat(0.001).into(),
        ..black()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Z).unwrap()),
        mirror,
        Transform::IDENTITY,
    );
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::new(0.0, 0.0, 10.0), -Vec3::Z).unwrap()),
        mirror,
        Transform::IDENTITY,
    );
    scene.settings.max_depth = MAX_DEPTH;
    scene.settings.threads = Some(1);
    let out = render(&scene, &|_| {}).unwrap();
    // Every bounce adds the emission once: depth + 1 times in all.
    let expected = 0.001 * f64::from(MAX_DEPTH + 1);
    assert_close(pixel(&out.image, 0, 0), Color::splat(expected), 1e-6);
    assert_eq!(out.rays[RayKind::Reflected], 4 * u64::from(MAX_DEPTH));

    scene.settings.max_depth = MAX_DEPTH + 1;
    assert!(matches!(
        render(&scene, &|_| {}),
        Err(RenderError::DepthTooLarge(_))
    ));
}

#[test]
fn a_mesh_renders_exactly_like_its_triangles_given_one_by_one() {
    use whitted::mesh::TriangleMesh;
    use whitted::shape::Triangle;
    // A small tetrahedron-like cap, moved and turned by a transform.
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.2, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let triangles = vec![[0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let placement = Transform::rotate(Vec3::new(1.0, 0.5, 0.0), 25.0).unwrap();
    let build = |as_mesh: bool| {
        let mut scene = scene_looking_down_z(40, 30, 50.0);
        scene.ambient = Color::splat(0.1);
        scene.lights.push(Light::Point {
            position: Vec3::new(2.0, 3.0, 4.0),
            intensity: Color::ONE,
            attenuation: Attenuation::NONE,
        });
        let m = scene.add_material(Material {
            specular: Color::splat(0.5).into(),
            ..Material::default()
        });
        if as_mesh {
            let mesh = TriangleMesh::new(positions.clone(), triangles.clone()).unwrap();
            let id = scene.add_mesh(mesh);
            scene.add_mesh_instance(id, m, placement);
        } else {
            for t in &triangles {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                scene.add_primitive(
                    Shape::Triangle(Triangle::new(a, b, c).unwrap()),
                    m,
                    placement,
                );
            }
        }
        scene
    };
    let mesh = render(&build(true), &|_| {}).unwrap();
    let single = render(&build(false), &|_| {}).unwrap();
    assert_eq!(mesh.image, single.image);
    assert!(mesh.image.data().iter().any(|&v| v > 0.2));
}

#[test]
fn vertex_normals_shade_a_flat_mesh_as_if_it_were_curved() {
    use whitted::mesh::TriangleMesh;
    // One big triangle facing +z whose vertex normals all lean towards +x:
    // lit from +x it must look brighter than its flat twin.
    let positions = vec![
        Vec3::new(-5.0, -5.0, 0.0),
        Vec3::new(5.0, -5.0, 0.0),
        Vec3::new(0.0, 5.0, 0.0),
    ];
    let lean = Vec3::new(1.0, 0.0, 1.0).normalize();
    let brightness = |normals: Option<Vec<Vec3>>| {
        let mut scene = scene_looking_down_z(3, 3, 10.0);
        scene.lights.push(Light::Directional {
            direction: -lean,
            intensity: Color::ONE,
        });
        let m = scene.add_material(Material {
            diffuse: Color::ONE.into(),
            ..black()
        });
        let mut mesh = TriangleMesh::new(positions.clone(), vec![[0, 1, 2]]).unwrap();
        if let Some(n) = normals {
            mesh = mesh.with_normals(n).unwrap();
        }
        let id = scene.add_mesh(mesh);
        scene.add_mesh_instance(id, m, Transform::IDENTITY);
        pixel(&rendered(&scene), 1, 1).r
    };
    let flat = brightness(None);
    let curved = brightness(Some(vec![lean; 3]));
    assert!((flat - lean.z).abs() < 1e-6, "{flat}");
    assert!((curved - 1.0).abs() < 1e-6, "{curved}");
}
