//! The caustic map against answers from physics: a clear ball passes all
//! the light it intercepts, a mirror sends on exactly the flux of the solid
//! angle it covers, and a glass ball focuses where the lens formula says.

use std::f64::consts::PI;

use super::*;
use crate::accel::AccelKind;
use crate::math::{Transform, Vec3};
use crate::shading::{Attenuation, Light, Texture};
use crate::shape::{Parallelogram, Plane, Shape, Sphere};
use crate::world::{MaterialId, Objects};

/// Objects, materials and lights, from which a map is built.
#[derive(Default)]
struct Setup {
    objects: Objects,
    materials: Vec<Material>,
    lights: Vec<Light>,
}

impl Setup {
    fn material(&mut self, material: Material) -> MaterialId {
        self.materials.push(material);
        MaterialId(self.materials.len() as u32 - 1)
    }

    fn add(&mut self, shape: Shape, material: MaterialId) {
        self.objects
            .add_primitive(shape, material, Transform::IDENTITY);
    }

    fn map(&self, count: u64, gather: u32, radius: f64) -> CausticMap {
        let world = World::build(&self.objects, AccelKind::default());
        let shading = Shading {
            materials: &self.materials,
            lights: &self.lights,
            background: Color::ZERO,
            ambient: Color::ZERO,
        };
        let settings = PhotonSettings {
            count,
            gather,
            radius: Some(radius),
        };
        CausticMap::build(&world, &shading, &settings, true).unwrap()
    }
}

fn matte() -> Material {
    Material::default()
}

/// Clear glass: everything refracted, no Fresnel reflection, no
/// absorption, no diffuse part.
fn clear_glass(ior: f64) -> Material {
    Material {
        diffuse: Texture::Constant(Color::ZERO),
        ambient: Texture::Constant(Color::ZERO),
        transmission: Texture::Constant(Color::ONE),
        ior,
        ..Material::default()
    }
}

/// A clear ball of radius `radius` at the origin lit from above by
/// sunlight of irradiance `sun`, over a matte floor `depth` below its
/// centre.
fn ball_over_floor(radius: f64, ior: f64, sun: Color, depth: f64) -> Setup {
    let mut setup = Setup::default();
    let glass = setup.material(clear_glass(ior));
    let floor = setup.material(matte());
    setup.add(
        Shape::Sphere(Sphere::new(Vec3::ZERO, radius).unwrap()),
        glass,
    );
    setup.add(
        Shape::Plane(Plane::new(Vec3::new(0.0, -depth, 0.0), Vec3::Y).unwrap()),
        floor,
    );
    setup.lights.push(Light::Directional {
        direction: -Vec3::Y,
        intensity: sun,
    });
    setup
}

fn total_power(map: &CausticMap) -> Color {
    map.photons().iter().map(Photon::power).sum()
}

fn within(got: Color, want: Color, relative: f64) -> bool {
    (got - want).abs().max_element() <= relative * want.max_element()
}

#[test]
fn a_clear_ball_sends_all_the_light_it_intercepts_onto_the_floor() {
    // Issue 19, test 0: irradiance E on a ball of radius R is E·πR² of
    // flux, and a clear ball loses none of it.
    let (radius, sun) = (0.7, Color::new(2.0, 1.0, 0.5));
    let setup = ball_over_floor(radius, 1.5, sun, 3.0);
    let map = setup.map(20_000, 50, 0.1);
    let expected = sun * (PI * radius * radius);
    let got = total_power(&map);
    assert!(within(got, expected, 0.01), "{got} vs {expected}");
    // Every photon kept is on the floor, arrived from above, after the
    // ball bent it (light straight from the sun is not a caustic).
    for p in map.photons() {
        assert!((p.position.y + 3.0).abs() < 1e-9, "{p:?}");
        assert!(p.incident().y < 0.0);
    }
    assert!(map.photons().len() > 5000);
}

#[test]
fn a_mirror_sends_the_flux_of_its_solid_angle_to_the_floor() {
    // Issue 19, test 1: a point light of intensity I one unit below the
    // middle of a 2×2 mirror facing down, a matte floor one unit below the
    // light. The mirror covers the solid angle Ω = 4 asin(a² / (a² + h²))
    // = 2π/3 seen from the light, so the floor's caustic carries I·Ω·kr.
    let mut setup = Setup::default();
    let kr = Color::new(1.0, 0.5, 0.25);
    let mirror = setup.material(Material {
        diffuse: Texture::Constant(Color::ZERO),
        reflection: Texture::Constant(kr),
        ..Material::default()
    });
    let floor = setup.material(matte());
    setup.add(
        Shape::Parallelogram(
            Parallelogram::new(
                Vec3::new(-1.0, 2.0, -1.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 2.0),
            )
            .unwrap(),
        ),
        mirror,
    );
    setup.add(
        Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap()),
        floor,
    );
    let intensity = Color::new(3.0, 1.0, 2.0);
    setup.lights.push(Light::Point {
        position: Vec3::new(0.0, 1.0, 0.0),
        intensity,
        attenuation: Attenuation::NONE,
    });
    let map = setup.map(30_000, 50, 0.1);
    let solid_angle = 4.0 * (0.5f64).asin();
    let expected = intensity * kr * solid_angle;
    let got = total_power(&map);
    assert!(within(got, expected, 0.01), "{got} vs {expected}");
    // The mirror's image of the light is 3 units above the floor: the
    // photons land inside the 6×6 square it projects.
    for p in map.photons() {
        assert!(p.position.y.abs() < 1e-9);
        assert!(p.position.x.abs() <= 3.0 + 1e-9 && p.position.z.abs() <= 3.0 + 1e-9);
    }
}

/// The brightest point of the caustic on the floor `depth` below the
/// ball's centre, searched on a coarse grid over the floor and a fine one
/// near the axis, and its irradiance.
fn brightest(map: &CausticMap, depth: f64) -> (Vec3, f64) {
    let mut best = (Vec3::ZERO, f64::NEG_INFINITY);
    let grids = [(2.0, 0.05), (0.3, 0.005)];
    for (half, step) in grids {
        let n = (2.0 * half / step) as i32;
        for i in 0..=n {
            for k in 0..=n {
                let (x, z) = (-half + f64::from(i) * step, -half + f64::from(k) * step);
                let p = Vec3::new(x, -depth, z);
                let e = map.irradiance(p, Vec3::Y).r;
                if e > best.1 {
                    best = (p, e);
                }
            }
        }
    }
    best
}

#[test]
fn a_glass_ball_focuses_sunlight_where_the_lens_formula_says() {
    // Issue 19, test 2: a ball lens of index n and radius R focuses
    // paraxial rays f = nR / (2(n - 1)) from its centre. On a floor there,
    // the brightest spot is on the axis, and its estimate keeps growing
    // with the photon count (a focus has no finite irradiance), where a
    // smooth patch of light would stay the same.
    let (radius, ior) = (1.0, 1.5);
    let f = ior * radius / (2.0 * (ior - 1.0));
    let setup = ball_over_floor(radius, ior, Color::ONE, f);
    let peaks: Vec<f64> = [10_000, 40_000]
        .into_iter()
        .map(|count| {
            let map = setup.map(count, 50, 0.5 * radius);
            let (spot, peak) = brightest(&map, f);
            let off_axis = Vec3::new(spot.x, 0.0, spot.z).length();
            assert!(off_axis <= 0.02 * radius, "{count} photons: {spot}");
            peak
        })
        .collect();
    // Rays at height h land c·h³ from the axis (third-order spherical
    // aberration), so the flux within r grows as r^(2/3) and the estimate
    // from a fixed number of photons as N²: 16 times for 4 times the
    // photons (measured 16.1). A smooth patch would not grow at all.
    assert!(peaks[1] > 8.0 * peaks[0], "{peaks:?}");
    // The same floor a focal length farther sees no such spike.
    let defocused = ball_over_floor(radius, ior, Color::ONE, 2.0 * f);
    let smooth: Vec<f64> = [10_000, 40_000]
        .into_iter()
        .map(|count| brightest(&defocused.map(count, 50, 0.5 * radius), 2.0 * f).1)
        .collect();
    assert!(smooth[1] < 1.2 * smooth[0], "{smooth:?}");
}

#[test]
fn the_cone_filter_estimates_a_uniform_irradiance() {
    // Photons spread evenly over a square at a known density: the
    // estimate away from the edges is that flux per area.
    let mut rng = crate::math::random::Rng::new(5);
    let (count, side) = (40_000, 4.0);
    let flux = Color::new(1.0, 2.0, 3.0);
    let photons: Vec<Photon> = (0..count)
        .map(|_| {
            let p = rng.point_in(Vec3::new(-2.0, 0.0, -2.0), Vec3::new(2.0, 0.0, 2.0));
            Photon::new(p, -Vec3::Y, flux / count as f64)
        })
        .collect();
    let map = CausticMap {
        tree: KdTree::build(photons),
        emitted: count,
        gather: 400,
        radius: 1.0,
    };
    let expected = flux / (side * side);
    // The cone filter trades noise for sharpness: each estimate within
    // 25%, their mean within 2%.
    let points = 200;
    let mut mean = Color::ZERO;
    for _ in 0..points {
        let p = rng.point_in(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
        let got = map.irradiance(p, Vec3::Y);
        assert!(within(got, expected, 0.25), "at {p}: {got} vs {expected}");
        mean += got / f64::from(points);
        // Seen from below, no photon arrives on that side.
        assert_eq!(map.irradiance(p, -Vec3::Y), Color::ZERO);
    }
    assert!(within(mean, expected, 0.02), "{mean} vs {expected}");
}

#[test]
fn the_map_is_the_same_for_any_thread_count() {
    let setup = ball_over_floor(1.0, 1.5, Color::ONE, 1.5);
    let map_with = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| setup.map(12_000, 50, 0.2))
    };
    let one = map_with(1);
    let three = map_with(3);
    assert_eq!(one.photons(), three.photons());
    let p = Vec3::new(0.01, -1.5, 0.0);
    assert_eq!(one.irradiance(p, Vec3::Y), three.irradiance(p, Vec3::Y));
}

#[test]
fn shadow_rays_stop_only_at_surfaces_that_bend_light() {
    let uv = DVec2::ZERO;
    let glass = clear_glass(1.5);
    assert!(bends_light(&glass));
    assert_eq!(shadow_pass_through(&glass, uv), Color::ZERO);
    // A window of index 1 and a dissolved leaf pass light straight on.
    let window = clear_glass(1.0);
    assert_eq!(shadow_pass_through(&window, uv), Color::ONE);
    let leaf = Material {
        opacity: Texture::Constant(Color::splat(0.25)),
        ..Material::default()
    };
    assert_eq!(shadow_pass_through(&leaf, uv), leaf.pass_through(uv));
}

#[test]
fn aiming_at_the_glass_loses_no_caustic_light() {
    // The ball over a bounded matte table 400 times its size: the sun's
    // photons are aimed at the ball alone, and carry the same flux as test
    // 0's; a mirror-less, glass-less scene shoots none at all.
    let (radius, sun) = (0.5, Color::new(1.0, 2.0, 3.0));
    let mut setup = ball_over_floor(radius, 1.5, sun, 2.0);
    setup.objects.primitives.pop();
    let table = setup.material(matte());
    setup.add(
        Shape::AxisBox(
            crate::shape::AxisBox::new(
                Vec3::new(-100.0, -2.0, -100.0),
                Vec3::new(100.0, -1.0, 100.0),
            )
            .unwrap(),
        ),
        table,
    );
    let map = setup.map(10_000, 50, 0.1);
    let expected = sun * (PI * radius * radius);
    let got = total_power(&map);
    assert!(within(got, expected, 0.01), "{got} vs {expected}");
    // Half the photons (the ball's share of its covering disk) are kept.
    assert!(map.photons().len() > 4_500, "{}", map.photons().len());
    let mut dull = setup;
    dull.materials[0] = matte();
    assert!(dull.map(10_000, 50, 0.1).photons().is_empty());
}

#[test]
fn mirrors_and_bending_glass_start_caustics_windows_do_not() {
    let mirror = Material {
        reflection: Texture::Constant(Color::splat(0.5)),
        ..matte()
    };
    assert!(aim::starts_caustics(&mirror));
    assert!(aim::starts_caustics(&clear_glass(1.33)));
    assert!(!aim::starts_caustics(&clear_glass(1.0)));
    assert!(!aim::starts_caustics(&matte()));
}
