//! Closed meshes against an inside test of their own: the winding number
//! (the solid angle the mesh subtends at a point, over 4π), which counts
//! no crossings at all.

use super::*;
use crate::math::random::Rng;
use crate::shape::Shape;
use crate::shape::testing::random_line_through;

/// A torus of `n` by `m` quads around the y axis, each split in two.
pub(crate) fn torus_mesh(major: f64, minor: f64, n: u32, m: u32) -> SmallMesh {
    let mut positions = Vec::new();
    for i in 0..n {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        for j in 0..m {
            let b = std::f64::consts::TAU * f64::from(j) / f64::from(m);
            let r = major + minor * b.cos();
            positions.push(Vec3::new(r * a.cos(), minor * b.sin(), r * a.sin()));
        }
    }
    let at = |i: u32, j: u32| (i % n) * m + j % m;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    SmallMesh::new(positions, triangles).unwrap()
}

/// The cube `[-1, 1]³`, its triangles facing in when `inward`.
pub(crate) fn cube_mesh(inward: bool) -> SmallMesh {
    let positions = (0..8)
        .map(|k| {
            Vec3::new(
                f64::from(k & 1),
                f64::from(k >> 1 & 1),
                f64::from(k >> 2 & 1),
            ) * 2.0
                - 1.0
        })
        .collect();
    let mut triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    if inward {
        triangles
            .iter_mut()
            .for_each(|t: &mut [u32; 3]| t.swap(1, 2));
    }
    SmallMesh::new(positions, triangles).unwrap()
}

/// The winding number of the mesh around `p`: near 1 inside, near 0
/// outside (Van Oosterom and Strackee's solid angle of each triangle).
fn winding(mesh: &SmallMesh, p: Vec3) -> f64 {
    let total: f64 = (0..mesh.len())
        .map(|i| {
            let [a, b, c] = mesh.corners(i).map(|v| v - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let det = a.dot(b.cross(c));
            let div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * det.atan2(div)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

fn meshes() -> Vec<SmallMesh> {
    vec![
        cube_mesh(false),
        cube_mesh(true),
        torus_mesh(1.0, 0.4, 12, 8),
        torus_mesh(0.6, 0.5, 7, 5),
    ]
}

#[test]
fn closed_meshes_are_closed_and_turned_to_face_out() {
    for mesh in meshes() {
        assert_eq!(mesh.open_edge(), None);
        assert!(mesh.data.volume() > 0.0);
        assert!((winding(&mesh, mesh.corners(0)[0] * 0.0 + Vec3::new(9.0, 0.0, 0.0))).abs() < 1e-9);
    }
    // The cube given inside out is turned round: its top faces up.
    let cube = cube_mesh(true);
    let down = Ray::new(Vec3::new(0.1, 0.2, 5.0), -Vec3::Z);
    let hit = cube.intersect(&down).unwrap();
    assert!((hit.t - 4.0).abs() < 1e-12);
    assert!(cube.surface(&down, &hit).normal.z > 0.99);
}

#[test]
fn open_and_inconsistent_meshes_name_the_edge() {
    let cube = cube_mesh(false);
    let mut triangles = cube.data.triangles.clone();
    triangles.remove(3);
    let open = SmallMesh::new(cube.data.positions.clone(), triangles.clone()).unwrap();
    assert_eq!(
        open.open_edge().unwrap().to_string(),
        "the edge from vertex 5 to vertex 6 of triangle 2 belongs to no other triangle: \
         the mesh is open there"
    );
    assert!(matches!(
        Shape::Mesh(open).solidity(),
        crate::shape::Solidity::Open(_)
    ));
    let mut flipped = cube.data.triangles.clone();
    flipped[5].swap(1, 2);
    let edge = SmallMesh::new(cube.data.positions.clone(), flipped)
        .unwrap()
        .open_edge()
        .unwrap();
    assert_eq!(edge.triangle, 5);
    assert!(edge.why.starts_with("runs the same way"), "{edge}");
}

#[test]
fn crossings_and_inside_test_agree_with_the_winding_number_on_random_lines() {
    let mut rng = Rng::new(31);
    for mesh in meshes() {
        let bounds = mesh.bounds();
        let mut crossed = 0;
        for _ in 0..200 {
            let (ray, start) = random_line_through(&mut rng, &bounds);
            let mut crossings = Crossings::new();
            mesh.crossings(&ray, &mut crossings);
            assert!(crossings.len().is_multiple_of(2), "{crossings:?}");
            assert!(crossings.windows(2).all(|w| w[0].hit.t <= w[1].hit.t));
            crossed += usize::from(!crossings.is_empty());
            for k in 0..200 {
                let t = start + f64::from(k) / 50.0 - 0.5;
                let p = ray.at(t);
                let w = winding(&mesh, p);
                if (w - 0.5).abs() > 0.49 {
                    let inside = w > 0.5;
                    let by_crossings = crossings
                        .iter()
                        .take_while(|c| c.hit.t < t)
                        .last()
                        .is_some_and(|c| c.entering);
                    assert_eq!(by_crossings, inside, "t = {t} along {ray:?}: {crossings:?}");
                    assert_eq!(mesh.contains(p), inside, "{p}");
                }
            }
        }
        assert!(crossed > 60, "{crossed}");
    }
}

#[test]
fn the_closest_hit_is_the_first_crossing_in_the_interval() {
    let mut rng = Rng::new(5);
    let mesh = torus_mesh(1.0, 0.4, 12, 8);
    for _ in 0..300 {
        let origin = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
        let ray = Ray::new(origin, rng.unit_vector());
        let mut crossings = Crossings::new();
        mesh.crossings(&ray, &mut crossings);
        let first = crossings.iter().find(|c| c.hit.t > 1e-9).map(|c| c.hit.t);
        let hit = mesh.intersect(&ray).map(|h| h.t);
        assert_eq!(hit.is_some(), first.is_some(), "{ray:?}");
        if let (Some(a), Some(b)) = (hit, first) {
            assert!((a - b).abs() < 1e-9, "{a} {b}");
        }
        assert_eq!(mesh.occluded(&ray), hit.is_some());
    }
}
