use super::*;
use crate::math::random::Rng;
use crate::shape::testing::{
    assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
    assert_surface_is_sane, assert_tangents_follow_uv,
};
use crate::shape::{Parallelogram, Shape, Triangle};

/// Control points `(i/3, j/3, ij/9)`: exactly the surface z = xy over the
/// unit square, with u = x and v = y.
fn saddle() -> BezierPatch {
    BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let (x, y) = (i as f64 / 3.0, j as f64 / 3.0);
            Vec3::new(x, y, x * y)
        })
    }))
    .unwrap()
}

/// A bumpy patch with no symmetry.
fn wavy() -> BezierPatch {
    BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let z = [
                [0.0, 0.8, -0.3, 0.2],
                [0.5, -1.0, 1.2, 0.0],
                [-0.4, 1.5, -0.8, 0.6],
                [0.3, 0.0, 0.7, -0.5],
            ][i][j];
            Vec3::new(
                i as f64 + 0.2 * j as f64,
                j as f64 - 0.1 * (i * i) as f64,
                z,
            )
        })
    }))
    .unwrap()
}

/// A dome-like quarter patch whose row u = 0 collapses to the apex
/// (0, 0, 1), as the centre of the teapot's lid.
fn collapsed() -> BezierPatch {
    BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let r = i as f64 / 3.0;
            let angle = std::f64::consts::FRAC_PI_2 * j as f64 / 3.0;
            Vec3::new(r * angle.cos(), r * angle.sin(), [1.0, 1.0, 0.8, 0.5][i])
        })
    }))
    .unwrap()
}

/// The parallelogram from `origin` along `a` and `b`, as a patch.
fn flat(origin: Vec3, a: Vec3, b: Vec3) -> BezierPatch {
    BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| origin + (i as f64 / 3.0) * a + (j as f64 / 3.0) * b)
    }))
    .unwrap()
}

/// The smallest t > 0 where the ray meets z = xy with x, y in [0, 1], and
/// the distance of that hit from the square's edges.
fn saddle_reference(ray: &Ray) -> Option<(f64, f64)> {
    let (o, d) = (ray.origin, ray.dir);
    let a = d.x * d.y;
    let b = o.x * d.y + o.y * d.x - d.z;
    let c = o.x * o.y - o.z;
    let roots: Vec<f64> = if a.abs() < 1e-300 {
        vec![-c / b]
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        vec![q / a, c / q]
    };
    roots
        .into_iter()
        .filter(|&t| t > 0.0 && t.is_finite())
        .filter_map(|t| {
            let p = ray.at(t);
            let edge = p.x.min(1.0 - p.x).min(p.y).min(1.0 - p.y);
            (edge >= 0.0).then_some((t, edge))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

#[test]
fn the_saddle_patch_is_z_equals_xy_in_hits_and_normals() {
    let patch = saddle();
    let mut rng = Rng::new(11);
    let mut hits = 0;
    for _ in 0..5000 {
        let origin = Vec3::new(0.5, 0.5, 0.25) + 3.0 * rng.unit_vector();
        let target = rng.point_in(Vec3::new(-0.2, -0.2, -0.2), Vec3::new(1.2, 1.2, 1.2));
        let ray = Ray::new(origin, (target - origin).normalize());
        let expected = saddle_reference(&ray);
        let found = patch.intersect(&ray);
        match (expected, found) {
            (Some((t, edge)), None) => assert!(edge < 1e-9, "missed {ray:?} at t = {t}"),
            (None, Some(hit)) => panic!("false hit {hit:?} for {ray:?}"),
            (Some((t, _)), Some(hit)) => {
                hits += 1;
                assert!((hit.t - t).abs() < 1e-9, "t {} != {t} for {ray:?}", hit.t);
                let s = patch.surface(&ray, &hit);
                let p = ray.at(t);
                let normal = Vec3::new(-p.y, -p.x, 1.0).normalize();
                assert!(
                    (s.normal - normal).length() < 1e-9,
                    "{:?} != {normal:?}",
                    s.normal
                );
                assert!((s.uv - DVec2::new(p.x, p.y)).length() < 1e-9);
                assert!((s.point - p).length() < 1e-9);
            }
            (None, None) => {}
        }
    }
    assert!(hits > 1500, "{hits}");
}

#[test]
fn a_flat_patch_is_the_parallelogram_through_its_corners() {
    let (origin, a, b) = (
        Vec3::new(0.3, -1.0, 2.0),
        Vec3::new(2.0, 0.5, -0.4),
        Vec3::new(-0.3, 1.5, 1.0),
    );
    let patch = flat(origin, a, b);
    let plane = Parallelogram::new(origin, a, b).unwrap();
    let mut rng = Rng::new(13);
    let mut hits = 0;
    for _ in 0..3000 {
        let from = origin + 0.5 * (a + b) + 6.0 * rng.unit_vector();
        let target = origin + rng.range(-0.2, 1.2) * a + rng.range(-0.2, 1.2) * b;
        let ray = Ray::new(from, target - from);
        let found = patch.intersect(&ray);
        match (plane.intersect(&ray), found) {
            (Some(expected), Some(hit)) => {
                hits += 1;
                assert!((hit.t - expected.t).abs() < 1e-12, "{hit:?} {expected:?}");
                let s = patch.surface(&ray, &hit);
                let p = origin + hit.u * a + hit.v * b;
                assert!((s.point - p).length() < 1e-12 && (p - ray.at(hit.t)).length() < 1e-9);
                assert!((s.normal - a.cross(b).normalize()).length() < 1e-12);
            }
            (None, None) => {}
            (expected, found) => {
                // Only a ray through the outline itself may be decided
                // differently by the two.
                let t = expected.map_or_else(|| found.unwrap().t, |h| h.t);
                let p = ray.at(t) - origin;
                let n = a.cross(b);
                let u = p.cross(b).dot(n) / n.length_squared();
                let v = a.cross(p).dot(n) / n.length_squared();
                let edge = u.min(1.0 - u).abs().min(v.min(1.0 - v).abs());
                assert!(edge < 1e-9, "{expected:?} vs {found:?} for {ray:?}");
            }
        }
    }
    assert!(hits > 1000, "{hits}");
}

#[test]
fn a_dense_tessellation_agrees_on_random_rays() {
    let patch = wavy();
    let n = 64;
    let net = *patch.points();
    let grid: Vec<Vec<Vec3>> = (0..=n)
        .map(|i| {
            (0..=n)
                .map(|j| evaluate(&net, i as f64 / n as f64, j as f64 / n as f64).point)
                .collect()
        })
        .collect();
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let [a, b, c, d] = [
                grid[i][j],
                grid[i + 1][j],
                grid[i + 1][j + 1],
                grid[i][j + 1],
            ];
            triangles.extend(Triangle::new(a, b, c).ok());
            triangles.extend(Triangle::new(a, c, d).ok());
        }
    }
    // The flat pieces are within h²/8 (|P_uu| + 2|P_uv| + |P_vv|) of the
    // surface, h = 1/n; the second derivatives are bounded by 6 (or 9)
    // times the largest second differences of the control points.
    let second = |f: &dyn Fn(usize, usize) -> Vec3| {
        (0..4)
            .flat_map(|i| (0..4).map(move |j| (i, j)))
            .map(|(i, j)| f(i, j).length())
            .fold(0.0, f64::max)
    };
    let uu = second(&|i, j| {
        if i < 2 {
            net[i + 2][j] - 2.0 * net[i + 1][j] + net[i][j]
        } else {
            Vec3::ZERO
        }
    });
    let vv = second(&|i, j| {
        if j < 2 {
            net[i][j + 2] - 2.0 * net[i][j + 1] + net[i][j]
        } else {
            Vec3::ZERO
        }
    });
    let uv = second(&|i, j| {
        if i < 3 && j < 3 {
            net[i + 1][j + 1] - net[i + 1][j] - net[i][j + 1] + net[i][j]
        } else {
            Vec3::ZERO
        }
    });
    let h = 1.0 / n as f64;
    let tessellation_error = h * h / 8.0 * (6.0 * uu + 18.0 * uv + 6.0 * vv);
    let mut rng = Rng::new(17);
    let b = patch.bounds();
    let (mut agreed, mut hits, mut worst) = (0, 0, 0.0f64);
    for _ in 0..600 {
        let from = b.centroid() + 3.0 * b.extent().length() * rng.unit_vector();
        let ray = Ray::new(from, (rng.point_in(b.min, b.max) - from).normalize());
        let reference = triangles
            .iter()
            .filter_map(|tri| tri.intersect(&ray).map(|hit| (hit.t, tri)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        match (patch.intersect(&ray), reference) {
            (Some(hit), Some((t, tri))) => {
                let [p0, p1, p2] = tri.vertices();
                let facet = (p1 - p0).cross(p2 - p0).normalize();
                let cosine = facet.dot(ray.dir).abs();
                if cosine > 0.1 {
                    worst = worst.max((hit.t - t).abs() * cosine);
                    assert!(
                        (hit.t - t).abs() * cosine <= tessellation_error,
                        "t {} vs {t} for {ray:?}",
                        hit.t
                    );
                }
                hits += 1;
                agreed += 1;
            }
            (None, None) => agreed += 1,
            (found, reference) => {
                // A silhouette or an edge: the ray passes within the
                // tessellation error of the outline of one of the two.
                let t = found.map_or_else(|| reference.unwrap().0, |h| h.t);
                let p = ray.at(t);
                let uv_hit = found.map(|h| (h.u, h.v));
                let near_edge =
                    uv_hit.is_none_or(|(u, v)| u.min(1.0 - u).min(v).min(1.0 - v) < 2.0 * h);
                let grazing = found
                    .is_none_or(|hit| patch.surface(&ray, &hit).normal.dot(ray.dir).abs() < 0.1);
                assert!(
                    near_edge || grazing,
                    "{found:?} vs {reference:?} at {p:?} for {ray:?}"
                );
            }
        }
    }
    assert!(agreed > 570 && hits > 200, "{agreed} {hits}");
    assert!(worst <= tessellation_error, "{worst} {tessellation_error}");
}

#[test]
fn a_collapsed_row_gives_finite_unit_normals_everywhere() {
    let patch = collapsed();
    for i in 0..=40 {
        for j in 0..=40 {
            let hit = ShapeHit {
                t: 1.0,
                u: i as f64 / 40.0,
                v: j as f64 / 40.0,
                part: 0,
            };
            let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
            let s = patch.surface(&ray, &hit);
            assert!((s.normal.length() - 1.0).abs() < 1e-12, "{s:?}");
            assert!(s.normal.z > 0.4, "{s:?}");
            assert!(s.dpdu.is_finite() && s.dpdv.is_finite());
        }
    }
    let down = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
    let hit = patch.intersect(&down).unwrap();
    assert!((hit.t - 4.0).abs() < 1e-9);
    let s = patch.surface(&down, &hit);
    assert!((s.normal - Vec3::Z).length() < 1e-5, "{s:?}");
    let shape = Shape::BezierPatch(patch);
    assert_surface_is_sane(&shape, 19);
    assert_no_nan_for_awkward_rays(&shape);
}

#[test]
fn rays_in_front_behind_beside_and_beyond_t_max() {
    let patch = saddle();
    let front = Ray::new(Vec3::new(0.5, 0.5, 2.0), -Vec3::Z);
    let hit = patch.intersect(&front).unwrap();
    assert!((hit.t - 1.75).abs() < 1e-14);
    assert!(patch.occluded(&front));
    let behind = Ray::new(Vec3::new(0.5, 0.5, 2.0), Vec3::Z);
    assert_eq!(patch.intersect(&behind), None);
    assert!(!patch.occluded(&behind));
    let beside = Ray::new(Vec3::new(1.0 + 1e-9, 0.5, 2.0), -Vec3::Z);
    assert_eq!(patch.intersect(&beside), None);
    let short = Ray::segment(Vec3::new(0.5, 0.5, 2.0), -Vec3::Z, 1.75);
    assert_eq!(patch.intersect(&short), None);
    let from_below = Ray::new(Vec3::new(0.5, 0.5, -2.0), Vec3::new(0.0, 0.0, 2.0));
    let hit = patch.intersect(&from_below).unwrap();
    assert!((hit.t - 1.125).abs() < 1e-14);
}

#[test]
fn a_ray_crossing_the_saddle_twice_takes_the_nearer_point() {
    // The line through (0.2, 0.9, 0.18) and (0.8, 0.3, 0.24), both on
    // z = xy, at t = 1 and t = 2.
    let ray = Ray::new(Vec3::new(-0.4, 1.5, 0.12), Vec3::new(0.6, -0.6, 0.06));
    let hit = saddle().intersect(&ray).unwrap();
    assert!((hit.t - 1.0).abs() < 1e-12, "{hit:?}");
    let later = Ray {
        t_min: 1.0 + 1e-9,
        ..ray
    };
    let hit = saddle().intersect(&later).unwrap();
    assert!((hit.t - 2.0).abs() < 1e-12, "{hit:?}");
}

#[test]
fn tangent_and_grazing_rays_never_give_nan() {
    let patch = saddle();
    for ray in [
        Ray::new(Vec3::new(-1.0, 0.0, 0.0), Vec3::X),
        Ray::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y),
        Ray::new(Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 0.0, 1.0)),
        Ray::new(Vec3::new(-1.0, 0.5, -0.5 + 1e-12), Vec3::new(1.0, 0.0, 0.5)),
    ] {
        assert_eq!(patch.intersect(&ray).is_some(), patch.occluded(&ray));
        if let Some(hit) = patch.intersect(&ray) {
            let s = patch.surface(&ray, &hit);
            assert!(
                hit.t.is_finite() && s.normal.is_finite() && s.uv.is_finite(),
                "{ray:?}"
            );
        }
    }
    let in_the_plane = flat(Vec3::ZERO, Vec3::X, Vec3::Y);
    let along = Ray::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::X);
    if let Some(hit) = in_the_plane.intersect(&along) {
        assert!(in_the_plane.surface(&along, &hit).normal.is_finite());
    }
}

#[test]
fn the_shared_edge_case_families_hold() {
    for patch in [
        saddle(),
        wavy(),
        collapsed(),
        flat(Vec3::ONE, Vec3::X, Vec3::new(0.0, 2.0, 1.0)),
    ] {
        let shape = Shape::BezierPatch(patch);
        assert_no_self_intersection(&shape, 23);
        assert_surface_is_sane(&shape, 29);
        assert_no_nan_for_awkward_rays(&shape);
        assert_tangents_follow_uv(&shape, 31);
    }
    let plane = Shape::BezierPatch(flat(Vec3::ONE, Vec3::X, Vec3::new(0.0, 2.0, 1.0)));
    assert_convex_exits_cleanly(&plane, 37);
}

#[test]
fn tiny_and_huge_patches_are_hit_like_the_unit_one() {
    for scale in [1e-6, 1e6] {
        let net = saddle().points().map(|row| row.map(|p| scale * p));
        let patch = BezierPatch::new(net).unwrap();
        let ray = Ray::new(scale * Vec3::new(0.5, 0.5, 2.0), -Vec3::Z);
        let hit = patch.intersect(&ray).unwrap();
        assert!((hit.t / scale - 1.75).abs() < 1e-12, "{hit:?}");
        assert_no_self_intersection(&Shape::BezierPatch(patch), 41);
    }
}

#[test]
fn degenerate_patches_are_refused() {
    let degenerate = |why| ShapeError::Degenerate {
        shape: "Bézier patch",
        why,
    };
    assert_eq!(
        BezierPatch::new([[Vec3::ONE; 4]; 4]),
        Err(degenerate("all its control points are equal"))
    );
    let line = std::array::from_fn(|i| std::array::from_fn(|j| (i * 4 + j) as f64 * Vec3::ONE));
    assert_eq!(
        BezierPatch::new(line),
        Err(degenerate(
            "its control points are collinear: it has no area"
        ))
    );
    let mut net = *saddle().points();
    net[2][1].y = f64::NAN;
    assert_eq!(
        BezierPatch::new(net),
        Err(ShapeError::NotFinite { what: "points" })
    );
    net[2][1].y = 1e31;
    assert!(matches!(
        BezierPatch::new(net),
        Err(ShapeError::OutOfRange { what: "points", .. })
    ));
    let tiny = saddle().points().map(|row| row.map(|p| 1e-31 * p));
    assert!(matches!(
        BezierPatch::new(tiny),
        Err(ShapeError::OutOfRange { .. })
    ));
}

#[test]
fn the_pieces_of_a_patch_are_the_patch() {
    for patch in [wavy(), collapsed(), saddle()] {
        let pieces: Vec<BezierPatch> = patch.pieces().collect();
        assert!(pieces.len() >= 16);
        let whole = patch.bounds().expanded(1e-6);
        for piece in &pieces {
            let b = piece.bounds();
            assert!(b.min.cmpge(whole.min).all() && b.max.cmple(whole.max).all());
            assert_eq!(piece.pieces().count(), 1);
        }
        let centre = patch.bounds().centroid();
        let mut rng = Rng::new(23);
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = centre + 4.0 * rng.unit_vector();
            let target = rng.point_in(patch.bounds().min, patch.bounds().max);
            let ray = Ray::new(origin, target - origin);
            let nearest = pieces
                .iter()
                .filter_map(|piece| piece.intersect(&ray))
                .min_by(|a, b| a.t.total_cmp(&b.t));
            match (patch.intersect(&ray), nearest) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert!((a.t - b.t).abs() < 1e-9 * a.t, "{a:?} {b:?}");
                    assert!((a.u - b.u).abs() < 1e-6 && (a.v - b.v).abs() < 1e-6);
                    let (sa, sb) = (patch.surface(&ray, &a), pieces[0].surface(&ray, &b));
                    assert!((sa.normal - sb.normal).length() < 1e-6);
                }
                (None, None) => {}
                (a, b) => panic!("{a:?} vs {b:?} for {ray:?}"),
            }
        }
        assert!(hits > 200, "{hits}");
    }
}
