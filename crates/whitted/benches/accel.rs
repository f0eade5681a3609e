//! Build and traversal benchmarks of every acceleration structure on a
//! seeded synthetic mesh (a bumpy sphere of triangles, so rays meet real
//! surfaces), reported as elements (boxes built, rays traced) per second.
//!
//! `cargo bench -p whitted --bench accel`. For the comparison with Embree on
//! real meshes use `whitted bench MESH.obj --rays DIR` instead.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use whitted::accel::{AccelKind, AccelerationStructure, Accelerator, QueryContext};
use whitted::math::random::Rng;
use whitted::math::{Aabb, Ray, Vec3};
use whitted::mesh::TriangleMesh;
use whitted::shape::RayShear;

/// A sphere of `rings × segments × 2` triangles with seeded radial bumps.
fn bumpy_sphere(rings: u32, segments: u32) -> TriangleMesh {
    let mut rng = Rng::new(11);
    let mut positions = Vec::new();
    for r in 0..=rings {
        let theta = std::f64::consts::PI * f64::from(r) / f64::from(rings);
        for s in 0..segments {
            let phi = std::f64::consts::TAU * f64::from(s) / f64::from(segments);
            let radius = 1.0 + 0.05 * rng.uniform();
            positions.push(
                radius
                    * Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.cos(),
                        theta.sin() * phi.sin(),
                    ),
            );
        }
    }
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let a = r * segments + s;
            let b = r * segments + (s + 1) % segments;
            let (c, d) = (a + segments, b + segments);
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    TriangleMesh::new(positions, triangles).expect("the sphere mesh is valid")
}

/// Seeded rays from a shell around the mesh towards points inside it.
fn rays(count: usize) -> Vec<Ray> {
    let mut rng = Rng::new(5);
    (0..count)
        .map(|_| {
            let origin = 3.0 * rng.unit_vector();
            let target = 0.8 * rng.unit_vector();
            Ray::new(origin, (target - origin).normalize())
        })
        .collect()
}

fn boxes(mesh: &TriangleMesh) -> Vec<Aabb> {
    (0..mesh.len() as u32)
        .map(|i| mesh.triangle_bounds(i))
        .collect()
}

fn build(c: &mut Criterion) {
    let mesh = bumpy_sphere(160, 320);
    let boxes = boxes(&mesh);
    let mut group = c.benchmark_group("build");
    group.sample_size(10);
    group.throughput(Throughput::Elements(boxes.len() as u64));
    for kind in AccelKind::ALL {
        if kind == AccelKind::Linear {
            continue;
        }
        group.bench_function(BenchmarkId::new(kind.name(), boxes.len()), |b| {
            b.iter(|| black_box(Accelerator::build(kind, black_box(&boxes))))
        });
    }
    group.finish();
}

fn traverse(c: &mut Criterion) {
    let mesh = bumpy_sphere(160, 320);
    let boxes = boxes(&mesh);
    let rays = rays(20_000);
    let mut group = c.benchmark_group("closest_hit");
    group.throughput(Throughput::Elements(rays.len() as u64));
    for kind in AccelKind::ALL {
        if kind == AccelKind::Linear {
            continue;
        }
        let accel = Accelerator::build(kind, &boxes);
        group.bench_function(BenchmarkId::new(kind.name(), mesh.len()), |b| {
            b.iter(|| {
                let mut ctx = QueryContext::default();
                let mut hits = 0usize;
                for ray in &rays {
                    let shear = RayShear::new(ray);
                    let mut local = *ray;
                    let t = accel.intersect(ray, &mut ctx, |i, t_max| {
                        local.t_max = t_max;
                        mesh.intersect(i, &local, &shear).map(|h| h.t)
                    });
                    hits += usize::from(t.is_some());
                }
                black_box(hits)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, build, traverse);
criterion_main!(benches);
