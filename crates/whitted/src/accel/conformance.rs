//! One conformance suite for every acceleration structure, with brute force
//! ([`super::Linear`]) as the oracle: seeded random scenes and the
//! degenerate cases that break structures (no primitives, one, identical
//! centroids, one huge primitive among tiny ones, flat axis-aligned meshes,
//! zero-area primitives), traced with random, inside-starting,
//! axis-parallel, edge-grazing and finite-segment rays.
//!
//! A structure's tests call [`assert_conforms`] with its [`AccelKind`].

use super::{AccelKind, AccelerationStructure, Accelerator, QueryContext, RayCoherence};
use crate::math::random::Rng;
use crate::math::{Aabb, Ray, Vec3};
use crate::shape::{AxisBox, Shape, Sphere, Triangle};

/// A primitive of a test scene.
#[derive(Clone, Debug)]
enum TestPrimitive {
    Shape(Shape),
    /// A zero-area primitive: a box (a point or a segment) and no surface.
    Degenerate(Aabb),
}

impl TestPrimitive {
    fn bounds(&self) -> Aabb {
        match self {
            TestPrimitive::Shape(s) => s.bounds(),
            TestPrimitive::Degenerate(b) => *b,
        }
    }

    fn intersect(&self, ray: &Ray) -> Option<f64> {
        match self {
            TestPrimitive::Shape(s) => s.intersect(ray).map(|h| h.t),
            TestPrimitive::Degenerate(_) => None,
        }
    }
}

fn sphere(center: Vec3, radius: f64) -> TestPrimitive {
    TestPrimitive::Shape(Shape::Sphere(Sphere::new(center, radius).unwrap()))
}

fn triangle(a: Vec3, b: Vec3, c: Vec3) -> Option<TestPrimitive> {
    Triangle::new(a, b, c)
        .ok()
        .map(|t| TestPrimitive::Shape(Shape::Triangle(t)))
}

fn random_triangle(rng: &mut Rng, around: Vec3, size: f64) -> TestPrimitive {
    loop {
        let mut corner = || around + size * rng.point_in(Vec3::splat(-1.0), Vec3::ONE);
        if let Some(t) = triangle(corner(), corner(), corner()) {
            return t;
        }
    }
}

/// `n` seeded random boxes: centres uniform in the cube of half-side
/// `spread` around the origin, half-extents between 5% and 100% of `size`
/// per axis. Shared by the structures' own tests.
pub(crate) fn random_boxes(rng: &mut Rng, n: usize, spread: f64, size: f64) -> Vec<Aabb> {
    (0..n)
        .map(|_| {
            let c = rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
            let half = size * rng.point_in(Vec3::splat(0.05), Vec3::ONE);
            Aabb::new(c - half, c + half)
        })
        .collect()
}

/// The named test scenes.
fn scenes() -> Vec<(&'static str, Vec<TestPrimitive>)> {
    let mut rng = Rng::new(2024);
    let mut out = vec![
        ("empty", Vec::new()),
        ("one sphere", vec![sphere(Vec3::new(0.5, -0.2, 0.1), 0.7)]),
    ];

    let spheres = (0..300)
        .map(|_| {
            let c = rng.point_in(Vec3::splat(-10.0), Vec3::splat(10.0));
            sphere(c, rng.range(0.05, 1.0))
        })
        .collect();
    out.push(("random spheres", spheres));

    let triangles = (0..400)
        .map(|_| {
            let c = rng.point_in(Vec3::splat(-10.0), Vec3::splat(10.0));
            let size = rng.range(0.1, 2.0);
            random_triangle(&mut rng, c, size)
        })
        .collect();
    out.push(("random triangles", triangles));

    let mut mixed: Vec<TestPrimitive> = Vec::new();
    for i in 0..300 {
        let c = rng.point_in(Vec3::splat(-5.0), Vec3::splat(5.0));
        let s = rng.range(0.05, 0.8);
        mixed.push(match i % 3 {
            0 => sphere(c, s),
            1 => random_triangle(&mut rng, c, s),
            _ => TestPrimitive::Shape(Shape::AxisBox(
                AxisBox::new(c - Vec3::splat(s), c + Vec3::new(s, 0.5 * s, 2.0 * s)).unwrap(),
            )),
        });
    }
    out.push(("mixed shapes", mixed));

    let mut with_degenerate: Vec<TestPrimitive> = (0..150)
        .map(|_| {
            let c = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
            random_triangle(&mut rng, c, 0.5)
        })
        .collect();
    for _ in 0..150 {
        let a = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
        let b = if rng.uniform() < 0.5 {
            a
        } else {
            rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0))
        };
        with_degenerate.push(TestPrimitive::Degenerate(Aabb::new(a, b)));
    }
    out.push(("zero-area primitives among triangles", with_degenerate));

    let same_centre = (1..=120)
        .map(|i| sphere(Vec3::new(1.0, 2.0, 3.0), 0.01 * f64::from(i)))
        .collect();
    out.push(("identical centroids", same_centre));

    let a = Vec3::new(-1.0, 0.0, 0.0);
    let b = Vec3::new(1.0, 0.0, 0.5);
    let c = Vec3::new(0.0, 1.0, 0.0);
    let copies = (0..100).filter_map(|_| triangle(a, b, c)).collect();
    out.push(("identical triangles", copies));

    let mut huge = vec![sphere(Vec3::new(50.0, 0.0, 0.0), 1000.0)];
    for _ in 0..200 {
        let c = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
        huge.push(sphere(c, 0.01));
    }
    out.push(("one huge primitive among tiny ones", huge));

    let mut flat = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let (x, y) = (f64::from(i), f64::from(j));
            let p = |dx: f64, dy: f64| Vec3::new(x + dx, y + dy, 0.0);
            flat.extend(triangle(p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)));
            flat.extend(triangle(p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)));
        }
    }
    out.push(("flat axis-aligned mesh", flat));
    out
}

/// The test rays for a scene with these bounds and primitive boxes.
fn rays(bounds: &Aabb, boxes: &[Aabb], rng: &mut Rng) -> Vec<Ray> {
    let bounds = if bounds.is_empty() {
        Aabb::new(Vec3::splat(-1.0), Vec3::ONE)
    } else {
        *bounds
    };
    let size = bounds.extent().length().max(1e-3);
    let centre = bounds.centroid();
    let mut out = Vec::new();
    for _ in 0..1500 {
        let origin = centre + 1.5 * size * rng.unit_vector();
        let target = rng.point_in(bounds.min, bounds.max);
        out.push(Ray::new(origin, target - origin));
    }
    for _ in 0..500 {
        let origin = rng.point_in(bounds.min, bounds.max);
        out.push(Ray::new(origin, rng.unit_vector()));
    }
    let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
    for i in 0..600 {
        let dir = axes[i % 6];
        let start = rng.point_in(bounds.min, bounds.max) - dir * size;
        out.push(Ray::new(start, dir));
    }
    // Rays grazing box corners, edges and faces of the primitives.
    for _ in 0..600.min(boxes.len() * 4) {
        let b = boxes[rng.below(boxes.len() as u32) as usize];
        let corner = Vec3::new(
            if rng.uniform() < 0.5 {
                b.min.x
            } else {
                b.max.x
            },
            if rng.uniform() < 0.5 {
                b.min.y
            } else {
                b.max.y
            },
            if rng.uniform() < 0.5 {
                b.min.z
            } else {
                b.max.z
            },
        );
        let dir = if rng.uniform() < 0.5 {
            axes[rng.below(6) as usize]
        } else {
            rng.unit_vector()
        };
        out.push(Ray::new(corner - dir * size, dir));
    }
    // Finite segments.
    for _ in 0..400 {
        let origin = centre + size * rng.unit_vector();
        let target = rng.point_in(bounds.min, bounds.max);
        out.push(Ray::segment(origin, target - origin, rng.range(0.0, 1.5)));
    }
    out
}

/// Closest hit through a structure: (t, primitive).
fn closest(
    accel: &Accelerator,
    prims: &[TestPrimitive],
    ray: &Ray,
    coherence: RayCoherence,
) -> Option<(f64, u32)> {
    let mut best = None;
    let mut ctx = QueryContext::new(coherence);
    let t = accel.intersect(ray, &mut ctx, |i, t_max| {
        let mut r = *ray;
        r.t_max = t_max;
        let t = prims[i as usize].intersect(&r)?;
        best = Some(i);
        Some(t)
    });
    t.zip(best)
}

/// Builds `kind` over every test scene and checks it against brute force,
/// with the rays said to be coherent and then incoherent (the hint may
/// change how a structure walks, never its answer).
pub(crate) fn assert_conforms(kind: AccelKind) {
    for coherence in [RayCoherence::Coherent, RayCoherence::Incoherent] {
        assert_conforms_with(kind, coherence);
    }
}

/// [`assert_conforms`] with one hint.
fn assert_conforms_with(kind: AccelKind, coherence: RayCoherence) {
    let mut rng = Rng::new(7);
    for (name, prims) in scenes() {
        let boxes: Vec<Aabb> = prims.iter().map(TestPrimitive::bounds).collect();
        let bounds = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        let oracle = Accelerator::build(AccelKind::Linear, &boxes);
        let accel = Accelerator::build(kind, &boxes);
        if let Err(why) = accel.validate(&boxes) {
            panic!("{} on {name}: invalid structure: {why}", kind.name());
        }
        for ray in rays(&bounds, &boxes, &mut rng) {
            let expected = closest(&oracle, &prims, &ray, coherence);
            let actual = closest(&accel, &prims, &ray, coherence);
            match (expected, actual) {
                (None, None) => {}
                (Some((te, pe)), Some((ta, pa))) if te == ta => {
                    // Ties at equal t may pick either primitive, but the one
                    // picked must really be hit there.
                    if pe != pa {
                        let mut r = ray;
                        r.t_max = f64::INFINITY;
                        assert_eq!(
                            prims[pa as usize].intersect(&r),
                            Some(ta),
                            "{} on {name}: tie broken towards a primitive not hit there",
                            kind.name()
                        );
                    }
                }
                _ => panic!(
                    "{} on {name}: closest hit {actual:?}, brute force {expected:?}, ray {ray:?}",
                    kind.name()
                ),
            }
            let mut ctx = QueryContext::new(coherence);
            let occluded = accel.occluded(&ray, &mut ctx, |i| {
                prims[i as usize].intersect(&ray).is_some()
            });
            assert_eq!(
                occluded,
                expected.is_some(),
                "{} on {name}: any-hit disagrees with brute force for {ray:?}",
                kind.name()
            );
        }
    }
}

#[test]
fn linear_conforms_to_itself() {
    assert_conforms(AccelKind::Linear);
}
