//! Shadow rays through clear spheres and a clear pane: each surface
//! crossed lets its material's share of the light through, the steps the
//! ray tree shows are the crossings in order, and they are the shadow rays
//! the render counts. Answered from the surfaces' crossings or by the
//! surface-to-surface walk (for materials that read (u, v)), the picture
//! and the counts are the same.

use whitted::integrator::{LightVerdict, RayKind, RayNode};
use whitted::math::{Transform, Vec3};
use whitted::render::{Scene, explain_pixel, render};
use whitted::shading::texture::Checker;
use whitted::shading::{Attenuation, Color, Light, Material, Texture};
use whitted::shape::{Polygon, Shape, Sphere};
use whitted::world::PrimitiveId;

mod common;
use common::{add_white_floor, black, scene_looking_down_z};

/// What each clear primitive's material lets through, by primitive number
/// (the floor is primitive 0, the pane 4).
const PASS: [f64; 5] = [0.0, 0.5, 0.8, 0.5, 0.6];

/// A white floor at z = 0 under two overlapping clear spheres of
/// different materials, lit from the side so that their shadows fall
/// beside them, and a third sphere of the first's material: in the same
/// place as the first with `twin` (the rays through both then take the
/// walk: a near tie), far out of the way without. A clear pane out of the
/// camera's view lies over part of the floor and of the first sphere's
/// shadow. With `walked`, each transmission is a checker of one colour:
/// the same light, but read at (u, v), so that shadow rays take the
/// surface-to-surface walk.
fn floor_under_glass(walked: bool, twin: bool) -> Scene {
    let mut scene = scene_looking_down_z(24, 24, 60.0);
    scene.ambient = Color::splat(0.1);
    add_white_floor(&mut scene);
    let glass = |scene: &mut Scene, pass: f64| {
        let pass = Color::splat(pass);
        let transmission = if walked {
            Texture::Checker(Checker {
                even: pass,
                odd: pass,
                size: 0.25,
            })
        } else {
            pass.into()
        };
        scene.add_material(Material {
            transmission,
            ..black()
        })
    };
    let (first, second) = (glass(&mut scene, PASS[1]), glass(&mut scene, PASS[2]));
    let spheres = [
        (Vec3::new(0.2, 0.1, 1.2), first),
        (Vec3::new(-0.4, -0.3, 1.6), second),
        if twin {
            (Vec3::new(0.2, 0.1, 1.2), first)
        } else {
            (Vec3::new(-40.0, 0.0, 1.2), first)
        },
    ];
    for (centre, material) in spheres {
        let sphere = Sphere::new(centre, 0.7).unwrap();
        scene.add_primitive(Shape::Sphere(sphere), material, Transform::IDENTITY);
    }
    let corners = [(3.15, 2.2), (3.4, 2.2), (3.4, 3.8), (3.15, 3.8)];
    let pane = Polygon::new(corners.map(|(x, y)| Vec3::new(x, y, 3.0)).to_vec()).unwrap();
    let pane_glass = glass(&mut scene, PASS[4]);
    scene.add_primitive(Shape::Polygon(pane), pane_glass, Transform::IDENTITY);
    scene.lights.push(Light::Point {
        position: Vec3::new(5.0, 4.0, 4.0),
        intensity: Color::ONE,
        attenuation: Attenuation::NONE,
    });
    scene
}

/// The shadow steps in `node`'s tree.
fn shadow_steps(node: &RayNode) -> usize {
    node.hit.iter().fold(0, |sum, hit| {
        let own: usize = hit.lights.iter().map(|l| l.shadow_rays.len()).sum();
        sum + own + hit.children.iter().map(shadow_steps).sum::<usize>()
    })
}

#[test]
fn light_through_clear_surfaces_is_the_product_of_each_crossing_in_order() {
    for twin in [false, true] {
        product_of_each_crossing_in_order(&floor_under_glass(false, twin));
    }
}

/// Checks the shadow rays of `scene`'s floor pixels ([`floor_under_glass`]).
fn product_of_each_crossing_in_order(scene: &Scene) {
    let output = render(scene, &|_| {}).unwrap();
    // By spheres' crossings (0, 2 or 4), and whether the pane is crossed.
    let (mut steps, mut crossed) = (0, [[0; 2]; 5]);
    for y in 0..24 {
        for x in 0..24 {
            let tree = explain_pixel(scene, (x, y), 0).unwrap().tree;
            steps += shadow_steps(&tree);
            let Some(hit) = tree.hit.as_ref().filter(|h| h.primitive == PrimitiveId(0)) else {
                continue;
            };
            let segments = &hit.lights[0].shadow_rays;
            let (last, crossings) = segments.split_last().unwrap();
            assert_eq!(last.blocker, None, "pixel {x},{y}");
            // Each step starts where the one before met a surface.
            let mut expected = Color::ONE;
            let mut from = hit.point;
            for segment in crossings {
                let (crossed, t) = segment.blocker.unwrap();
                assert!((segment.origin - from).length() < 1e-9, "pixel {x},{y}");
                assert!(t > 0.0, "pixel {x},{y}");
                from = segment.origin + t * segment.direction;
                expected *= Color::splat(PASS[crossed.0 as usize]);
            }
            assert!((last.origin - from).length() < 1e-9, "pixel {x},{y}");
            let verdict = hit.lights[0].verdict;
            if crossings.is_empty() {
                assert_eq!(verdict, LightVerdict::Lit, "pixel {x},{y}");
            } else {
                let transmittance = expected;
                assert_eq!(
                    verdict,
                    LightVerdict::Attenuated { transmittance },
                    "pixel {x},{y}"
                );
            }
            let pane = crossings
                .iter()
                .any(|c| c.blocker.unwrap().0 == PrimitiveId(4));
            crossed[crossings.len() - usize::from(pane)][usize::from(pane)] += 1;
        }
    }
    // Floor pixels lit directly, through one sphere (two crossings) and
    // through both (four); and through the pane alone, with one sphere and
    // with both.
    let [none, _, one, _, both] = crossed;
    assert!(none[0] > 20 && one[0] > 10 && both[0] > 10, "{crossed:?}");
    assert!(none[1] > 20 && one[1] > 10 && both[1] > 10, "{crossed:?}");
    assert_eq!(steps as u64, output.rays[RayKind::Shadow]);
}

#[test]
fn crossings_and_the_surface_walk_give_the_same_picture_and_shadow_rays() {
    for twin in [false, true] {
        let crossed = render(&floor_under_glass(false, twin), &|_| {}).unwrap();
        let walked = render(&floor_under_glass(true, twin), &|_| {}).unwrap();
        assert_eq!(crossed.image, walked.image, "twin: {twin}");
        let shadow_rays = crossed.rays[RayKind::Shadow];
        assert_eq!(shadow_rays, walked.rays[RayKind::Shadow], "twin: {twin}");
        // More shadow rays than camera hits: some crossed the glass.
        assert!(shadow_rays > 24 * 24 + 100, "twin: {twin}");
    }
}
