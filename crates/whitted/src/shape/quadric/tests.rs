use std::f64::consts::{PI, TAU};

use super::reference::{first_root, value};
use super::*;
use crate::math::random::Rng;
use crate::shape::testing::{
    assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
    assert_surface_is_sane, assert_tangents_follow_uv,
};
use crate::shape::{Cone, Cylinder, Shape, Sphere};

fn boxed(min: [f64; 3], max: [f64; 3]) -> Option<Aabb> {
    Some(Aabb::new(Vec3::from_array(min), Vec3::from_array(max)))
}

/// `x² + y² + z² = 1`.
fn unit_sphere() -> Quadric {
    Quadric::new([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0], None).unwrap()
}

/// `x² + y² - z² = 1` for |z| ≤ 2: a hyperboloid of one sheet, a waist.
fn hyperboloid() -> Quadric {
    Quadric::new(
        [1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        boxed([-3.0, -3.0, -2.0], [3.0, 3.0, 2.0]),
    )
    .unwrap()
}

/// `z = x² + y²` for z ≤ 1: a bowl opening upwards.
fn paraboloid() -> Quadric {
    Quadric::new(
        [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0],
        boxed([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0]),
    )
    .unwrap()
}

/// A variety of quadrics, with cross terms, for the property checks.
fn assorted() -> Vec<Quadric> {
    let q = |k: [f64; 10], clip| Quadric::new(k, clip).unwrap();
    vec![
        unit_sphere(),
        hyperboloid(),
        paraboloid(),
        // A tilted ellipsoid off the origin.
        q([2.0, 1.0, 0.5, 0.6, -0.3, 0.2, -1.0, 0.4, 0.3, -2.0], None),
        // Two sheets: z² - x² - y² = 1, clipped.
        q(
            [-1.0, -1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
            boxed([-2.0, -2.0, -3.0], [2.0, 2.0, 3.0]),
        ),
        // A double cone x² + y² = z², clipped.
        q(
            [1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            boxed([-1.5, -1.5, -1.0], [1.5, 1.5, 1.5]),
        ),
        // A slanted elliptic cylinder.
        q(
            [1.0, 2.0, 0.5, 0.5, 0.4, -0.7, 0.1, 0.0, 0.0, -1.0],
            boxed([-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]),
        ),
        // A saddle z = x² - y².
        q(
            [1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0],
            boxed([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]),
        ),
        // A plane x + 2y - z = 0.5.
        q(
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 2.0, -1.0, -0.5],
            boxed([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]),
        ),
        // A large ellipsoid far from the origin.
        q(
            [1.0, 1.0, 4.0, 0.0, 0.0, 0.0, -2e4, 0.0, 0.0, 1e8 - 2.5e5],
            None,
        ),
    ]
}

/// A random ray: from outside the box towards a point in it, or from a
/// random point in it in a random direction.
fn random_ray(rng: &mut Rng, b: Aabb) -> Ray {
    let size = b.extent().length();
    let target = rng.point_in(b.min, b.max);
    if rng.below(4) == 0 {
        return Ray::new(target, rng.unit_vector() * rng.range(0.1, 10.0));
    }
    let origin = b.centroid() + size * rng.range(0.6, 3.0) * rng.unit_vector();
    Ray::new(origin, (target - origin) * rng.range(0.1, 10.0))
}

/// `|n·d̂|` at `t` along the ray: 0 where the ray is tangent.
fn incidence(q: &Quadric, ray: &Ray, t: f64) -> f64 {
    let n = q.data.form.gradient(ray.at(t));
    (n.normalize().dot(ray.dir.normalize())).abs()
}

/// True when `p` lies within `margin` of a face of the clipping box.
fn near_clip_face(q: &Quadric, p: Vec3, margin: f64) -> bool {
    q.clip().is_some_and(|b| {
        let inner = (p - b.min).min(b.max - p);
        inner.min_element() < margin
    })
}

#[test]
fn agrees_with_a_dense_numeric_reference_on_random_rays() {
    let mut rng = Rng::new(17);
    for q in assorted() {
        let b = q.bounds();
        let size = b.extent().length();
        let clip = q.clip().unwrap_or(b.expanded(1e-3 * size));
        let (mut compared, mut hits) = (0, 0);
        let mut worst: f64 = 0.0;
        for _ in 0..1500 {
            let ray = random_ray(&mut rng, b);
            let t_far = 20.0 * size / ray.dir.length();
            let reference = first_root(&q.coefficients(), &ray, clip, t_far, 4000);
            let ours = q.intersect(&ray).map(|h| h.t);
            let doubtful = |t: Option<f64>| {
                t.is_some_and(|t| {
                    incidence(&q, &ray, t) < 1e-6
                        || near_clip_face(&q, ray.at(t), 1e-6 * size)
                        || t * ray.dir.length() < 1e-6 * size
                })
            };
            if doubtful(reference) || doubtful(ours) {
                continue;
            }
            compared += 1;
            match (ours, reference) {
                (Some(t), Some(r)) => {
                    hits += 1;
                    let error = (t - r).abs() / r.abs();
                    worst = worst.max(error);
                    assert!(error < 1e-7, "{q:?} {ray:?}: t = {t}, reference {r}");
                }
                (None, None) => {}
                _ => panic!("{q:?} {ray:?}: ours {ours:?}, reference {reference:?}"),
            }
        }
        assert!(
            compared > 1200 && hits > 300,
            "{q:?}: {compared} rays, {hits} hits"
        );
        assert!(worst < 1e-7, "{worst}");
    }
}

#[test]
fn the_unit_sphere_is_the_known_answer() {
    let q = unit_sphere();
    let sphere = Sphere::new(Vec3::ZERO, 1.0).unwrap();
    let mut rng = Rng::new(5);
    let mut hits = 0;
    for _ in 0..2000 {
        let ray = random_ray(&mut rng, q.bounds());
        // The exact roots of |o + t d|² = 1.
        let (o, d) = (ray.origin, ray.dir);
        let (a, b, c) = (d.dot(d), o.dot(d), o.dot(o) - 1.0);
        let disc = b * b - a * c;
        let exact = (disc >= 0.0)
            .then(|| [(-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a])
            .and_then(|roots| roots.into_iter().find(|&t| t > 0.0));
        let ours = q.intersect(&ray);
        if exact.is_some_and(|t| incidence(&q, &ray, t) < 1e-6) {
            continue;
        }
        assert_eq!(ours.is_some(), exact.is_some(), "{ray:?}");
        let (Some(hit), Some(t)) = (ours, exact) else {
            continue;
        };
        hits += 1;
        assert!((hit.t - t).abs() <= 1e-12 * t, "{} {t}", hit.t);
        let s = q.surface(&ray, &hit);
        let expected = sphere.surface(&ray, &ShapeHit::at(t));
        // Within t's error along the ray.
        let along = 1e-12 * (1.0 + t * d.length());
        assert!((s.point - expected.point).length() < along, "{ray:?}");
        assert!((s.normal - expected.normal).length() < along);
        assert!(
            (s.uv - expected.uv).length() < 10.0 * along || (s.uv.x - expected.uv.x).abs() > 0.99
        );
        assert!((s.dpdu - expected.dpdu).length() < 1e-9);
        assert!((s.dpdv - expected.dpdv).length() < 1e-9);
    }
    assert!(hits > 1000, "{hits}");
}

/// Checks that `q` finds the same hits as `shape` on random rays, to 1e-9
/// relative in t and in the normal, away from tangency and the rims.
fn reproduces(q: &Quadric, shape: &Shape, seed: u64) {
    let mut rng = Rng::new(seed);
    let b = shape.bounds();
    let size = b.extent().length();
    let mut hits = 0;
    for _ in 0..3000 {
        let ray = random_ray(&mut rng, b);
        let ours = q.intersect(&ray);
        let theirs = shape.intersect(&ray);
        let doubtful = |t: f64| {
            incidence(q, &ray, t) < 1e-6
                || near_clip_face(q, ray.at(t), 1e-9 * size)
                || t * ray.dir.length() < 1e-9 * size
        };
        if ours.is_some_and(|h| doubtful(h.t)) || theirs.is_some_and(|h| doubtful(h.t)) {
            continue;
        }
        assert_eq!(
            ours.is_some(),
            theirs.is_some(),
            "{ray:?}: {ours:?} {theirs:?}"
        );
        let (Some(ours), Some(theirs)) = (ours, theirs) else {
            continue;
        };
        hits += 1;
        assert!(
            (ours.t - theirs.t).abs() <= 1e-9 * theirs.t,
            "{ours:?} {theirs:?}"
        );
        let n = q.surface(&ray, &ours).normal;
        let expected = shape.surface(&ray, &theirs).normal;
        assert!((n - expected).length() < 1e-9, "{n} {expected}");
    }
    assert!(hits > 1000, "{hits}");
}

#[test]
fn special_cases_reproduce_the_sphere_cylinder_and_cone() {
    let (cx, cy, cz, r) = (0.5, -1.0, 2.0, 1.5);
    let sphere = Quadric::new(
        [
            1.0,
            1.0,
            1.0,
            0.0,
            0.0,
            0.0,
            -2.0 * cx,
            -2.0 * cy,
            -2.0 * cz,
            cx * cx + cy * cy + cz * cz - r * r,
        ],
        None,
    )
    .unwrap();
    let center = Vec3::new(cx, cy, cz);
    reproduces(&sphere, &Shape::Sphere(Sphere::new(center, r).unwrap()), 3);

    let (radius, height) = (0.7, 2.5);
    let cylinder = Quadric::new(
        [
            1.0,
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            -radius * radius,
        ],
        boxed([-radius, -radius, 0.0], [radius, radius, height]),
    )
    .unwrap();
    let open = Cylinder::new(radius, height, false).unwrap();
    reproduces(&cylinder, &Shape::Cylinder(open), 4);

    // x² + y² = (r0 + k z)².
    let (r0, r1, h) = (1.2, 0.3, 2.0);
    let k = (r1 - r0) / h;
    let cone = Quadric::new(
        [
            1.0,
            1.0,
            -k * k,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            -2.0 * r0 * k,
            -r0 * r0,
        ],
        boxed([-r0, -r0, 0.0], [r0, r0, h]),
    )
    .unwrap();
    reproduces(&cone, &Shape::Cone(Cone::new(r0, r1, h, false).unwrap()), 5);
}

#[test]
fn ray_in_front_hits_the_near_side_with_an_outward_normal() {
    let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    let hit = unit_sphere().intersect(&ray).unwrap();
    assert_eq!(hit.t, 4.0);
    assert_eq!(unit_sphere().surface(&ray, &hit).normal, -Vec3::Z);
}

#[test]
fn ray_starting_inside_hits_the_far_side_facing_outward() {
    let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
    let hit = unit_sphere().intersect(&ray).unwrap();
    assert!((hit.t - 0.5).abs() < 1e-15);
    assert_eq!(unit_sphere().surface(&ray, &hit).normal, Vec3::Y);
    // Inside the waist of the hyperboloid, the wall faces away from the axis.
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let hit = hyperboloid().intersect(&ray).unwrap();
    assert!((hit.t - 1.0).abs() < 1e-15);
    assert!((hyperboloid().surface(&ray, &hit).normal - Vec3::X).length() < 1e-15);
}

#[test]
fn quadric_behind_the_ray_or_beside_it_is_missed() {
    let behind = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
    assert_eq!(unit_sphere().intersect(&behind), None);
    assert!(!unit_sphere().occluded(&behind));
    let beside = Ray::new(Vec3::new(1.0 + 1e-9, 0.0, -5.0), Vec3::Z);
    assert_eq!(unit_sphere().intersect(&beside), None);
    let short = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 4.0);
    assert_eq!(unit_sphere().intersect(&short), None);
}

#[test]
fn tangent_and_grazing_rays_give_no_nan() {
    let tangent = Ray::new(Vec3::new(1.0, 0.0, -5.0), Vec3::Z);
    let hit = unit_sphere().intersect(&tangent).unwrap();
    assert!((hit.t - 5.0).abs() < 1e-7);
    let s = unit_sphere().surface(&tangent, &hit);
    assert!((s.normal - Vec3::X).length() < 1e-6);
    // Along a ruling of the hyperboloid (it contains straight lines), and
    // along the wall of the cylinder: no hit or a finite one.
    let cylinder = Quadric::new(
        [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        boxed([-1.0, -1.0, 0.0], [1.0, 1.0, 2.0]),
    )
    .unwrap();
    for (q, ray) in [
        (
            hyperboloid(),
            Ray::new(Vec3::new(1.0, -2.0, -2.0), Vec3::new(0.0, 1.0, 1.0)),
        ),
        (cylinder, Ray::new(Vec3::new(1.0, 0.0, -1.0), Vec3::Z)),
    ] {
        if let Some(hit) = q.intersect(&ray) {
            assert!(hit.t.is_finite());
            let s = q.surface(&ray, &hit);
            assert!(s.normal.is_finite() && s.uv.is_finite() && s.dpdu.is_finite());
        }
    }
}

#[test]
fn a_root_outside_the_bounds_is_skipped_for_the_second() {
    // From above, the ray meets the bowl's surface twice; clipped at z ≤ 1
    // the first root (z = 4) is outside and the second (z = 0.25) kept.
    let q = paraboloid();
    let ray = Ray::new(Vec3::new(-3.0, 0.0, 5.5), Vec3::new(1.0, 0.0, -1.5));
    let hit = q.intersect(&ray).unwrap();
    let p = ray.at(hit.t);
    assert!((p - Vec3::new(0.5, 0.0, 0.25)).length() < 1e-12, "{p}");
    // The unclipped surface would have been hit first, at x = -2.
    assert!(value(&q.coefficients(), Vec3::new(-2.0, 0.0, 4.0)).abs() < 1e-15);
}

#[test]
fn linear_equations_are_solved_along_a_paraboloid_axis_and_for_planes() {
    let down = Ray::new(Vec3::new(0.5, 0.0, 5.0), -Vec3::Z);
    let hit = paraboloid().intersect(&down).unwrap();
    assert_eq!(hit.t, 4.75);
    let s = paraboloid().surface(&down, &hit);
    let expected = Vec3::new(1.0, 0.0, -1.0).normalize();
    assert!((s.normal - expected).length() < 1e-15, "{}", s.normal);
    let plane = Quadric::new(
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -0.25],
        boxed([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]),
    )
    .unwrap();
    let ray = Ray::new(Vec3::new(0.1, -3.0, 0.2), Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(plane.intersect(&ray).unwrap().t, 1.625);
    let parallel = Ray::new(Vec3::new(0.1, 0.25, -3.0), Vec3::Z);
    assert_eq!(plane.intersect(&parallel), None);
}

#[test]
fn degenerate_parameters_are_refused() {
    let sphere = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
    let degenerate = |k: [f64; 10], clip| {
        matches!(
            Quadric::new(k, clip),
            Err(ShapeError::Degenerate {
                shape: "quadric",
                ..
            })
        )
    };
    assert!(degenerate(
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        boxed([0.0; 3], [1.0; 3])
    ));
    assert!(degenerate(
        [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        None
    ));
    assert!(degenerate(
        [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        None
    ));
    assert!(degenerate(sphere, boxed([2.0; 3], [3.0; 3])));
    for (min, max) in [
        ([0.0, 0.0, 0.0], [1.0, -1.0, 1.0]),
        ([0.0; 3], [1.0, 0.0, 1.0]),
    ] {
        let clip = Some(Aabb {
            min: Vec3::from_array(min),
            max: Vec3::from_array(max),
        });
        assert!(degenerate(sphere, clip));
    }
    let mut infinite = sphere;
    infinite[4] = f64::NAN;
    assert_eq!(
        Quadric::new(infinite, None),
        Err(ShapeError::NotFinite { what: "e" })
    );
    infinite[4] = f64::INFINITY;
    assert_eq!(
        Quadric::new(infinite, None),
        Err(ShapeError::NotFinite { what: "e" })
    );
    let mut huge = sphere;
    huge[9] = -1e40;
    assert!(matches!(
        Quadric::new(huge, None),
        Err(ShapeError::OutOfRange { what: "j", .. })
    ));
    let far = boxed([0.0; 3], [1e31, 1.0, 1.0]);
    assert!(matches!(
        Quadric::new(sphere, far),
        Err(ShapeError::OutOfRange { what: "bounds", .. })
    ));
    let nan = Some(Aabb {
        min: Vec3::new(f64::NAN, 0.0, 0.0),
        max: Vec3::ONE,
    });
    assert!(matches!(
        Quadric::new(sphere, nan),
        Err(ShapeError::NotFinite { what: "bounds" })
    ));
}

#[test]
fn bounds_hold_the_ellipsoid_and_the_clipped_part() {
    let q = Quadric::new([4.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -4.0], None).unwrap();
    let b = q.bounds();
    assert!(b.min.cmple(Vec3::new(-1.0, -2.0, -2.0)).all());
    assert!((b.max - Vec3::new(1.0, 2.0, 2.0)).length() < 1e-5);
    let clipped = Quadric::new(
        [4.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -4.0],
        boxed([0.0, -5.0, -5.0], [5.0, 5.0, 1.0]),
    )
    .unwrap();
    let b = clipped.bounds();
    assert!(b.min.x == 0.0 && b.max.z == 1.0 && b.max.x < 1.001 && b.min.y > -2.001);
    assert_eq!(
        hyperboloid().bounds(),
        boxed([-3.0, -3.0, -2.0], [3.0, 3.0, 2.0]).unwrap()
    );
}

#[test]
fn uv_are_spherical_angles_about_the_centre() {
    let q = hyperboloid();
    let ray = Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
    let s = q.surface(&ray, &q.intersect(&ray).unwrap());
    assert!((s.uv - DVec2::new(0.75, 0.5)).length() < 1e-12, "{}", s.uv);
    assert!((s.dpdu - TAU * Vec3::X).length() < 1e-12, "{}", s.dpdu);
    assert!((s.dpdv - PI * Vec3::Z).length() < 1e-12, "{}", s.dpdv);
}

#[test]
fn edge_case_families_hold_for_every_kind() {
    for (seed, q) in assorted().into_iter().enumerate() {
        let seed = seed as u64;
        let shape = Shape::Quadric(q);
        assert_no_self_intersection(&shape, 100 + seed);
        assert_surface_is_sane(&shape, 200 + seed);
        assert_no_nan_for_awkward_rays(&shape);
    }
    for q in [unit_sphere(), assorted()[3].clone(), assorted()[9].clone()] {
        assert_convex_exits_cleanly(&Shape::Quadric(q), 300);
    }
}

#[test]
fn tangents_are_the_derivatives_of_the_parametric_form() {
    // The star-shaped ones (not the cone with its apex near the centre, the
    // saddle through it, or the plane).
    let star_shaped = assorted()
        .into_iter()
        .enumerate()
        .filter(|(i, _)| ![5, 7, 8].contains(i));
    for (seed, q) in star_shaped {
        assert_tangents_follow_uv(&Shape::Quadric(q), 400 + seed as u64);
    }
}
