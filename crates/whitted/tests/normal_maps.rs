//! Renders of bump- and normal-mapped surfaces whose pixel values are
//! known: a height ramp tilts the normal by its slope, downhill; a normal
//! map tilts it along the texture's axes, whatever their handedness.

use std::f64::consts::FRAC_1_SQRT_2;
use std::sync::Arc;

use whitted::math::{DVec2, Transform, Vec3};
use whitted::mesh::TriangleMesh;
use whitted::render::Camera;
use whitted::render::Scene;
use whitted::render::render;
use whitted::shading::Bump;
use whitted::shading::Color;
use whitted::shading::Light;
use whitted::shading::Material;
use whitted::shading::Texture;
use whitted::shading::texture::{ImageData, ImageTexture, Wrap};
use whitted::shape::{Parallelogram, Shape};
use whitted::world::MaterialId;

/// A 9×9 picture of the square [-2, 2]² in the plane z = 0, seen from
/// z = 5, lit by one directional light towards `to_light` (unit).
fn lit_square(to_light: Vec3) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 30.0).unwrap();
    let mut scene = Scene::new(camera);
    scene.settings.width = 9;
    scene.settings.height = 9;
    scene.lights.push(Light::Directional {
        direction: -to_light,
        intensity: Color::ONE,
    });
    scene
}

fn matte(bump: Bump) -> Material {
    Material {
        ambient: Texture::default(),
        diffuse: Color::ONE.into(),
        bump: Some(bump),
        ..Material::default()
    }
}

/// Heights rising linearly in u from 0 to 1 over [0, 1], clamped outside.
fn height_ramp_in_u() -> Texture {
    let texels = (0..64).map(|x| [(x as f32 + 0.5) / 64.0; 3]).collect();
    Texture::Image(ImageTexture {
        wrap: Wrap::Clamp,
        ..ImageTexture::new(Arc::new(ImageData::new(64, 1, texels).unwrap()))
    })
}

/// The square [-2, 2]² as a two-triangle mesh with texture coordinates
/// `uv` at the corners (-2, -2), (2, -2), (2, 2), (-2, 2).
fn add_square_mesh(scene: &mut Scene, uv: [DVec2; 4], material: MaterialId) {
    let positions = vec![
        Vec3::new(-2.0, -2.0, 0.0),
        Vec3::new(2.0, -2.0, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
        Vec3::new(-2.0, 2.0, 0.0),
    ];
    let mesh = TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]])
        .unwrap()
        .with_uvs(uv.to_vec())
        .unwrap();
    let id = scene.add_mesh(mesh);
    scene.add_mesh_instance(id, material, Transform::IDENTITY);
}

/// The centre pixel's red value.
fn centre(scene: &Scene) -> f64 {
    let film = render(scene, &|_| {}).unwrap().image;
    f64::from(film.pixel(4, 4)[0])
}

#[test]
fn a_height_ramp_on_a_parallelogram_tilts_the_normal_45_degrees_downhill() {
    // u runs along +x over 4 units; heights 0 to 4 (strength 4): slope 1,
    // so the normal is (-1, 0, 1)/√2.
    let bump = Bump::Height {
        texture: height_ramp_in_u(),
        strength: 4.0,
    };
    let square = Parallelogram::new(
        Vec3::new(-2.0, -2.0, 0.0),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(0.0, 4.0, 0.0),
    )
    .unwrap();
    for (to_light, expected) in [
        (Vec3::Z, FRAC_1_SQRT_2),
        (Vec3::new(-1.0, 0.0, 1.0).normalize(), 1.0),
        (Vec3::new(1.0, 0.0, 1.0).normalize(), 0.0),
        (Vec3::new(0.0, 1.0, 1.0).normalize(), 0.5),
    ] {
        let mut scene = lit_square(to_light);
        let m = scene.add_material(matte(bump.clone()));
        scene.add_primitive(Shape::Parallelogram(square), m, Transform::IDENTITY);
        let value = centre(&scene);
        assert!((value - expected).abs() < 1e-5, "{to_light}: {value}");
    }
}

#[test]
fn a_height_ramp_on_a_mesh_follows_its_texture_coordinates() {
    // u runs along +y, v along -x: the heights rise towards +y, and the
    // normal leans towards -y.
    let uv = [
        DVec2::new(0.0, 1.0),
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, 1.0),
    ];
    let bump = Bump::Height {
        texture: height_ramp_in_u(),
        strength: 4.0,
    };
    for (to_light, expected) in [
        (Vec3::Z, FRAC_1_SQRT_2),
        (Vec3::new(0.0, -1.0, 1.0).normalize(), 1.0),
        (Vec3::new(0.0, 1.0, 1.0).normalize(), 0.0),
    ] {
        let mut scene = lit_square(to_light);
        let m = scene.add_material(matte(bump.clone()));
        add_square_mesh(&mut scene, uv, m);
        let value = centre(&scene);
        assert!((value - expected).abs() < 1e-5, "{to_light}: {value}");
    }
}

#[test]
fn a_normal_map_on_mirrored_texture_coordinates_tilts_towards_growing_u() {
    // The map says "45° towards the image's right" everywhere; u grows
    // along -x (the layout is mirrored), so the normal is (-1, 0, 1)/√2.
    let uv = [
        DVec2::new(1.0, 0.0),
        DVec2::new(0.0, 0.0),
        DVec2::new(0.0, 1.0),
        DVec2::new(1.0, 1.0),
    ];
    let bump = Bump::Normal {
        texture: Texture::Constant(Color::new(1.0, 0.5, 1.0)),
        strength: 1.0,
        flip_green: false,
    };
    for (to_light, expected) in [
        (Vec3::new(-1.0, 0.0, 1.0).normalize(), 1.0),
        (Vec3::new(1.0, 0.0, 1.0).normalize(), 0.0),
    ] {
        let mut scene = lit_square(to_light);
        let m = scene.add_material(matte(bump.clone()));
        add_square_mesh(&mut scene, uv, m);
        let value = centre(&scene);
        assert!((value - expected).abs() < 1e-6, "{to_light}: {value}");
    }
}

#[test]
fn a_flat_normal_map_renders_exactly_like_no_map() {
    let flat = Bump::Normal {
        texture: Texture::Constant(Color::new(0.5, 0.5, 1.0)),
        strength: 1.0,
        flip_green: false,
    };
    let to_light = Vec3::new(0.3, -0.4, 1.0).normalize();
    let pictures = [Some(flat), None].map(|bump| {
        let mut scene = lit_square(to_light);
        let m = scene.add_material(Material {
            bump,
            ..matte(Bump::Height {
                texture: Texture::default(),
                strength: 0.0,
            })
        });
        add_square_mesh(&mut scene, [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y], m);
        render(&scene, &|_| {}).unwrap().image
    });
    assert_eq!(pictures[0], pictures[1]);
}

#[test]
fn a_light_behind_a_bumped_surface_lights_nothing() {
    // The tilted normal (-1, 0, 1)/√2 would see a light grazing in from
    // below the surface at (-1, 0, -0.1); the geometric surface hides it.
    let bump = Bump::Normal {
        texture: Texture::Constant(Color::new(0.0, 0.5, 1.0)),
        strength: 1.0,
        flip_green: false,
    };
    let mut scene = lit_square(Vec3::new(-1.0, 0.0, -0.1).normalize());
    let m = scene.add_material(matte(bump));
    add_square_mesh(&mut scene, [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y], m);
    assert_eq!(centre(&scene), 0.0);
}
