//! The torus's quartic solved two ways on the same rays: the shipped
//! Ferrari's closed form with two Newton steps and a check
//! (`Torus::intersect`) against the recursive derivative intervals alone
//! (`Torus::intersect_by_monotone`, its fallback, kept for this
//! measurement), both after the same move of the ray's origin
//! near the centre. The ray families are those of the accuracy comparison
//! in the torus's tests (near and far cameras, through the hole, grazing,
//! spindle tori); the figures are in docs/performance-log.md ("Torus solvers").
//!
//! `cargo bench -p whitted --bench torus_solver`.

use std::f64::consts::TAU;
use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use whitted::math::random::Rng;
use whitted::math::{Ray, Vec3};
use whitted::shape::Torus;

/// The rays of one family, 500 per torus.
type Family = Vec<(Torus, Ray)>;

fn torus(major: f64, minor: f64) -> Torus {
    Torus::new(major, minor).expect("the radii are valid")
}

/// Ordinary, fat, horn, spindle and thin tori.
fn tori() -> Vec<Torus> {
    [(1.0, 0.25), (1.0, 0.6), (0.7, 0.7), (0.5, 1.0), (1.0, 0.02)]
        .map(|(a, b)| torus(a, b))
        .to_vec()
}

fn size(t: &Torus) -> f64 {
    t.major() + t.minor()
}

/// A ray from `distance` sizes away at a random point inside the bounds.
fn from_afar(t: &Torus, rng: &mut Rng, distance: f64) -> Ray {
    let bounds = t.bounds();
    let target = rng.point_in(bounds.min, bounds.max);
    let w = rng.unit_vector();
    Ray::new(target - distance * size(t) * w, w)
}

/// A ray from 3 sizes away through a point of the hole.
fn through_the_hole(t: &Torus, rng: &mut Rng) -> Ray {
    let rho = (t.major() - t.minor()) * rng.uniform().sqrt();
    let phi = rng.range(0.0, TAU);
    let y = rng.range(-1.0, 1.0) * t.minor();
    let target = Vec3::new(rho * phi.cos(), y, rho * phi.sin());
    let w = rng.unit_vector();
    Ray::new(target - 3.0 * size(t) * w, w)
}

/// A ray along the tangent plane at a random point, 1e-3 to 1e-6 of the
/// size inside the solid.
fn grazing(t: &Torus, rng: &mut Rng) -> Ray {
    let (phi, theta) = (rng.range(0.0, TAU), rng.range(0.0, TAU));
    let ring = t.major() + t.minor() * theta.cos();
    let point = Vec3::new(ring * phi.cos(), t.minor() * theta.sin(), -ring * phi.sin());
    let normal = Vec3::new(
        theta.cos() * phi.cos(),
        theta.sin(),
        -theta.cos() * phi.sin(),
    );
    let w = normal.cross(rng.unit_vector()).normalize();
    let depth = [1e-3, 1e-4, 1e-5, 1e-6][rng.below(4) as usize] * size(t);
    Ray::new(point - depth * normal - 3.0 * size(t) * w, w)
}

fn family(tori: &[Torus], rng: &mut Rng, make: impl Fn(&Torus, &mut Rng) -> Ray) -> Family {
    tori.iter()
        .flat_map(|t| (0..500).map(|_| (*t, make(t, rng))).collect::<Vec<_>>())
        .collect()
}

fn solvers(c: &mut Criterion) {
    let mut rng = Rng::new(17);
    let spindles = [torus(0.5, 1.0), torus(0.9, 1.0), torus(0.2, 1.0)];
    let families = [
        (
            "near",
            family(&tori(), &mut rng, |t, r| from_afar(t, r, 3.0)),
        ),
        (
            "far",
            family(&tori(), &mut rng, |t, r| from_afar(t, r, 1e4)),
        ),
        ("hole", family(&tori()[..2], &mut rng, through_the_hole)),
        ("grazing", family(&tori(), &mut rng, grazing)),
        (
            "spindle",
            family(&spindles, &mut rng, |t, r| from_afar(t, r, 3.0)),
        ),
    ];
    let mut group = c.benchmark_group("torus_solver");
    group.sample_size(20);
    for (name, rays) in &families {
        group.throughput(Throughput::Elements(rays.len() as u64));
        group.bench_function(BenchmarkId::new("monotone", name), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|(t, ray)| t.intersect_by_monotone(black_box(ray)).is_some())
                    .count()
            })
        });
        group.bench_function(BenchmarkId::new("ferrari", name), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|(t, ray)| t.intersect(black_box(ray)).is_some())
                    .count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, solvers);
criterion_main!(benches);
