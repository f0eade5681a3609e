//! Area lights through the whole tracer: the penumbra of a sphere under a
//! disk light where similar triangles put it, the light's own shape seen
//! glowing, and shadow rays that do not stop at the light itself.

use whitted::accel::AccelKind;
use whitted::integrator::{RayCounts, RecursionLimits, Shading, Whitted};
use whitted::math::{Ray, Transform, Vec3};
use whitted::render::{Camera, Scene};
use whitted::shading::{AreaLight, Color, Emitter, Light, Material, Texture};
use whitted::shape::{Plane, Shape, Sphere};
use whitted::world::World;

/// Radius and height of the disk light, facing down on the axis.
const LIGHT_RADIUS: f64 = 0.5;
const LIGHT_HEIGHT: f64 = 4.0;
/// Radius and centre height of the occluding sphere, on the axis.
const BALL_RADIUS: f64 = 0.3;
const BALL_HEIGHT: f64 = 2.0;

/// A white floor (kd 1, nothing else) under the disk light, with the
/// sphere between them when `ball`.
fn scene(ball: bool, accel: AccelKind) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 1.0, -5.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
    let mut scene = Scene::new(camera);
    scene.settings.accel = accel;
    let white = scene.add_material(Material {
        ambient: Texture::default(),
        diffuse: Color::ONE.into(),
        ..Material::default()
    });
    scene.add_primitive(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap()),
        white,
        Transform::IDENTITY,
    );
    if ball {
        let center = Vec3::new(0.0, BALL_HEIGHT, 0.0);
        let sphere = Sphere::new(center, BALL_RADIUS).unwrap();
        scene.add_primitive(Shape::Sphere(sphere), white, Transform::IDENTITY);
    }
    scene
        .add_light(Light::Area(AreaLight {
            emitter: Emitter::Disk {
                center: Vec3::new(0.0, LIGHT_HEIGHT, 0.0),
                normal: -Vec3::Y,
                radius: LIGHT_RADIUS,
            },
            radiance: Color::ONE,
            samples: 4096,
        }))
        .unwrap();
    scene
}

/// The colour of the floor at `(x, 0, 0)`, and of what a ray from there
/// straight up meets first.
struct Probe<'a> {
    whitted: Whitted<'a>,
}

impl Probe<'_> {
    fn floor(&self, x: f64) -> f64 {
        let ray = Ray::new(Vec3::new(x, 1e-3, 0.0), -Vec3::Y);
        let mut counts = RayCounts::default();
        self.whitted.trace_primary(&ray, &mut counts).color.r
    }

    fn looking_up(&self, x: f64) -> Color {
        let ray = Ray::new(Vec3::new(x, 1e-3, 0.0), Vec3::Y);
        let mut counts = RayCounts::default();
        self.whitted.trace_primary(&ray, &mut counts).color
    }
}

fn with_probe<R>(scene: &Scene, f: impl FnOnce(&Probe<'_>) -> R) -> R {
    let world = World::build(&scene.objects, scene.settings.accel);
    let shading = Shading {
        materials: &scene.materials,
        lights: &scene.lights,
        background: scene.background,
        ambient: scene.ambient,
    };
    let limits = RecursionLimits {
        max_depth: 0,
        min_weight: 0.0,
        ray_budget: 0,
    };
    f(&Probe {
        whitted: Whitted::new(&world, shading, limits),
    })
}

/// Where on the floor (x > 0) the line through the light's edge point
/// `(edge, LIGHT_HEIGHT)` grazes the sphere's outline on its +x side, in
/// the plane through the axis: an edge of the penumbra by similar
/// triangles (with the sphere's tangent, not its centre section).
fn tangent_on_floor(edge: f64) -> f64 {
    // Distance from the sphere's centre to the line from (x, 0) to the
    // edge point, minus the radius: negative while the line cuts it.
    let gap = |x: f64| {
        let (dx, dy) = (edge - x, LIGHT_HEIGHT);
        let (cx, cy) = (-x, BALL_HEIGHT);
        (dx * cy - dy * cx).abs() / (dx * dx + dy * dy).sqrt() - BALL_RADIUS
    };
    let (mut lo, mut hi) = (0.0, 3.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        // The line leaves the sphere on its +x side for large x.
        if gap(mid) < 0.0 || (edge - mid) * BALL_HEIGHT / LIGHT_HEIGHT + mid < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The smallest x in `[0, 3]` where `lit(x)` holds, for `lit` false then
/// true along x.
fn first_where(lit: impl Fn(f64) -> bool) -> f64 {
    let (mut lo, mut hi) = (0.0, 3.0);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if lit(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[test]
fn the_penumbra_of_a_sphere_lies_where_similar_triangles_put_it() {
    let (outer_predicted, inner_predicted) = (
        tangent_on_floor(-LIGHT_RADIUS),
        tangent_on_floor(LIGHT_RADIUS),
    );
    // The thin-occluder approximation says about the same.
    let ratio = BALL_HEIGHT / (LIGHT_HEIGHT - BALL_HEIGHT);
    let width_predicted = outer_predicted - inner_predicted;
    assert!((width_predicted - 2.0 * LIGHT_RADIUS * ratio).abs() < 0.1 * width_predicted);
    for accel in [AccelKind::Bvh, AccelKind::Linear] {
        let open = scene(false, accel);
        let shaded = scene(true, accel);
        with_probe(&open, |open| {
            with_probe(&shaded, |shaded| {
                // The same point has the same samples in both scenes: the
                // floor is fully lit where nothing is blocked, bit for bit.
                let outer = first_where(|x| shaded.floor(x) == open.floor(x));
                let inner = first_where(|x| shaded.floor(x) > 0.0);
                let tolerance = 0.01 * width_predicted;
                assert!(
                    (outer - outer_predicted).abs() < tolerance,
                    "{accel:?}: outer edge {outer} vs {outer_predicted}"
                );
                assert!(
                    (inner - inner_predicted).abs() < tolerance,
                    "{accel:?}: inner edge {inner} vs {inner_predicted}"
                );
                // Half the light is hidden about half-way across.
                let middle =
                    shaded.floor(0.5 * (inner + outer)) / open.floor(0.5 * (inner + outer));
                assert!((0.3..0.7).contains(&middle), "{middle}");
            })
        });
    }
}

#[test]
fn the_light_is_seen_glowing_and_does_not_shadow_itself() {
    let open = scene(false, AccelKind::Bvh);
    with_probe(&open, |probe| {
        // Straight up from the floor, the disk shows π L.
        let glow = probe.looking_up(0.0);
        assert_eq!(glow, Color::splat(std::f64::consts::PI));
        // Beside it, the sky (black).
        assert_eq!(probe.looking_up(2.0), Color::ZERO);
        // Under the light, the floor gets π L sin²θ: no sample is stopped
        // by the light's own surface.
        let sin2 = LIGHT_RADIUS.powi(2) / (LIGHT_RADIUS.powi(2) + LIGHT_HEIGHT.powi(2));
        let exact = std::f64::consts::PI * sin2;
        let floor = probe.floor(0.0);
        assert!(
            ((floor - exact) / exact).abs() < 0.005,
            "{floor} vs {exact}"
        );
    });
}
