//! The kd-tree against brute force: the shared conformance suite, then the
//! cases a kd-tree gets wrong first: flat boxes, rays in and on split
//! planes, ranges ending on them, degenerate and unplaceable boxes.
//!
//! Here the primitives are the boxes themselves: a primitive is hit where
//! the ray enters its box, so both structures see exactly the same hits.

use super::build::default_max_depth;
use super::node::{KdNode, NodeKind};
use super::traverse::{SHALLOW, STACK_CAPACITY};
use super::{KdTree, KdTreeBuildParams};
use crate::accel::conformance::{assert_conforms, random_boxes};
use crate::accel::{
    AccelKind, AccelerationStructure, Accelerator, QueryContext, RayCoherence, TraversalCounters,
};
use crate::math::random::Rng;
use crate::math::{Aabb, Ray, Vec3};
use crate::shape::Triangle;
use crate::shape::clipped_triangle_bounds;

/// Where `ray` enters `b` within `(ray.t_min, t_max)`.
fn box_hit(b: &Aabb, ray: &Ray, t_max: f64) -> Option<f64> {
    let mut r = *ray;
    r.t_max = t_max;
    let (near, _) = b.intersect_ray(&r)?;
    (near > r.t_min && near < t_max).then_some(near)
}

/// The closest hit and the any-hit answer through `accel`.
fn trace(
    accel: &Accelerator,
    boxes: &[Aabb],
    ray: &Ray,
    coherence: RayCoherence,
) -> (Option<f64>, bool) {
    let mut ctx = QueryContext::new(coherence);
    let closest = accel.intersect(ray, &mut ctx, |i, t_max| {
        box_hit(&boxes[i as usize], ray, t_max)
    });
    let any = accel.occluded(ray, &mut ctx, |i| {
        box_hit(&boxes[i as usize], ray, ray.t_max).is_some()
    });
    (closest, any)
}

/// Builds a kd-tree over `boxes`, validates it and checks every ray
/// against brute force. Returns the tree.
fn assert_matches_brute_force(boxes: &[Aabb], rays: &[Ray], what: &str) -> KdTree {
    let tree = KdTree::build(boxes);
    if let Err(why) = tree.validate(boxes) {
        panic!("{what}: invalid tree: {why}");
    }
    let accel = Accelerator::KdTree(tree.clone());
    let oracle = Accelerator::build(AccelKind::Linear, boxes);
    let mut hits = 0;
    with_either_start(|start, coherence| {
        hits = 0;
        for ray in rays {
            let expected = trace(&oracle, boxes, ray, coherence);
            assert_eq!(
                trace(&accel, boxes, ray, coherence),
                expected,
                "{what}, {start}: {ray:?}"
            );
            // Whole leaves, as `World` asks for them.
            let closest =
                tree.intersect_in_leaf_order(ray, &mut QueryContext::new(coherence), |r, t_max| {
                    r.map(|e| tree.indices()[e as usize])
                        .fold(None, |found, i| {
                            box_hit(&boxes[i as usize], ray, found.unwrap_or(t_max)).or(found)
                        })
                });
            let any = tree.occluded_in_leaf_order(ray, &mut QueryContext::new(coherence), |r| {
                r.map(|e| tree.indices()[e as usize])
                    .any(|i| box_hit(&boxes[i as usize], ray, ray.t_max).is_some())
            });
            assert_eq!(
                (closest, any),
                expected,
                "{what}, {start}, whole leaves: {ray:?}"
            );
            hits += usize::from(expected.1);
        }
    });
    assert!(hits > 0 || boxes.is_empty(), "{what}: no ray hits anything");
    tree
}

fn random_rays(rng: &mut Rng, n: usize, spread: f64) -> Vec<Ray> {
    (0..n)
        .map(|_| {
            let origin = rng.point_in(Vec3::splat(-2.0 * spread), Vec3::splat(2.0 * spread));
            let target = rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// Every split plane of the tree, as (axis, position).
fn splits(tree: &KdTree) -> Vec<(usize, f32)> {
    tree.nodes
        .iter()
        .filter_map(|n| match n.kind() {
            NodeKind::Interior { axis, split, .. } => Some((axis, split)),
            NodeKind::Leaf { .. } => None,
        })
        .collect()
}

fn unit(v: usize) -> Vec3 {
    Vec3::AXES[v]
}

/// Runs `body` with rays said to be coherent (the walk from the root),
/// then incoherent (the descent to the origin's leaf first), giving it the
/// start's name and the hint.
fn with_either_start(mut body: impl FnMut(&str, RayCoherence)) {
    body("walk from the root", RayCoherence::Coherent);
    body("descent to the origin's leaf", RayCoherence::Incoherent);
}

/// Checks that `accel` and `oracle` give every ray the same closest hit
/// and any-hit answer with either start, primitives hit by `hit(i, ray,
/// t_max)`. Returns how many rays hit something.
fn assert_agrees_with(
    accel: &Accelerator,
    oracle: &Accelerator,
    rays: &[Ray],
    hit: impl Fn(u32, &Ray, f64) -> Option<f64>,
) -> usize {
    let mut hits = 0;
    with_either_start(|start, coherence| {
        hits = 0;
        for ray in rays {
            let mut c = QueryContext::new(coherence);
            let expected = oracle.intersect(ray, &mut c, |i, t| hit(i, ray, t));
            let actual = accel.intersect(ray, &mut c, |i, t| hit(i, ray, t));
            assert_eq!(actual, expected, "{start}: {ray:?}");
            let any = |a: &Accelerator, c: &mut QueryContext| {
                a.occluded(ray, c, |i| hit(i, ray, ray.t_max).is_some())
            };
            let expected_any = any(oracle, &mut c);
            assert_eq!(any(accel, &mut c), expected_any, "{start}: {ray:?}");
            hits += usize::from(expected_any);
        }
    });
    hits
}

#[test]
fn kdtree_conforms_to_brute_force_with_either_start() {
    // The suite runs the coherent and the incoherent hint in turn.
    assert_conforms(AccelKind::KdTree);
}

#[test]
fn kdtree_is_listed_before_linear_and_found_by_name() {
    assert_eq!(AccelKind::from_name("kdtree"), Some(AccelKind::KdTree));
    assert_eq!(AccelKind::ALL.last(), Some(&AccelKind::Linear));
    let accel = Accelerator::build(AccelKind::KdTree, &[]);
    assert_eq!(accel.kind(), AccelKind::KdTree);
}

/// Stored leaves holding no primitive.
fn empty_leaves(tree: &KdTree) -> usize {
    let empty = |n: &&KdNode| matches!(n.kind(), NodeKind::Leaf { count: 0, .. });
    tree.nodes.iter().filter(empty).count()
}

/// Interior nodes without a below child, and without an above child.
fn missing_children(tree: &KdTree) -> (usize, usize) {
    tree.nodes.iter().fold((0, 0), |(b, a), n| match n.kind() {
        NodeKind::Interior { below, above, .. } => {
            (b + usize::from(!below), a + usize::from(above == 0))
        }
        NodeKind::Leaf { .. } => (b, a),
    })
}

#[test]
fn children_without_primitives_are_not_stored_and_rays_skip_their_cells() {
    // Sparse boxes: cutting off empty space pays on both sides of planes.
    let mut rng = Rng::new(23);
    let boxes = random_boxes(&mut rng, 2_000, 200.0, 1.0);
    let rays = random_rays(&mut rng, 2_000, 200.0);
    let tree = assert_matches_brute_force(&boxes, &rays, "sparse boxes");
    assert_eq!(empty_leaves(&tree), 0);
    let (no_below, no_above) = missing_children(&tree);
    assert!(no_below > 10 && no_above > 10, "{no_below} {no_above}");
}

#[test]
fn random_boxes_of_every_size_build_valid_trees_within_the_depth_limit() {
    let mut rng = Rng::new(11);
    for n in [0, 1, 2, 3, 10, 100, 1_000, 10_000] {
        let boxes = random_boxes(&mut rng, n, 50.0, 2.0);
        let tree = KdTree::build(&boxes);
        tree.validate(&boxes)
            .unwrap_or_else(|why| panic!("{n} boxes: {why}"));
        let stats = tree.stats();
        assert!(
            stats.references >= n && stats.leaves <= stats.nodes,
            "{stats:?}"
        );
        assert!(stats.max_depth <= default_max_depth(n), "{stats:?}");
        assert_eq!(empty_leaves(&tree), usize::from(n == 0), "{n}");
        if n >= 1_000 {
            // A real tree: far cheaper than testing everything, and few
            // boxes copied into many leaves.
            assert!(stats.sah_cost < 0.05 * n as f64, "{n}: {stats:?}");
            assert!(stats.references < 3 * n, "{n}: {stats:?}");
        }
    }
    let boxes = random_boxes(&mut rng, 2_000, 50.0, 2.0);
    assert_matches_brute_force(&boxes, &random_rays(&mut rng, 2_000, 50.0), "random boxes");
}

#[test]
fn degenerate_inputs_terminate_with_valid_trees() {
    let mut rng = Rng::new(12);
    let cube = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let point = Aabb::new(Vec3::splat(2.0), Vec3::splat(2.0));
    let mut huge_among_tiny = random_boxes(&mut rng, 500, 1.0, 0.01);
    huge_among_tiny.push(Aabb::new(Vec3::splat(-1e6), Vec3::splat(1e6)));
    let segments = (0..300)
        .map(|i| {
            let x = f64::from(i) * 0.1;
            Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.5, 0.0, 0.0))
        })
        .collect();
    let points = (0..300)
        .map(|_| {
            let p = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
            Aabb::new(p, p)
        })
        .collect();
    let nested = (1..=200)
        .map(|i| Aabb::new(Vec3::splat(-f64::from(i)), Vec3::splat(f64::from(i))))
        .collect();
    let cases: Vec<(&str, Vec<Aabb>)> = vec![
        ("identical boxes", vec![cube; 1_000]),
        ("identical points", vec![point; 1_000]),
        ("one huge box among tiny ones", huge_among_tiny),
        ("collinear segments", segments),
        ("scattered points", points),
        ("nested boxes", nested),
    ];
    for (what, boxes) in cases {
        let tree = KdTree::build(&boxes);
        tree.validate(&boxes)
            .unwrap_or_else(|why| panic!("{what}: {why}"));
        let stats = tree.stats();
        assert!(
            stats.max_depth <= default_max_depth(boxes.len()),
            "{what}: {stats:?}"
        );
    }
    let rays = random_rays(&mut rng, 500, 2.0);
    assert_matches_brute_force(&vec![cube; 100], &rays, "identical boxes");
}

#[test]
fn flat_boxes_are_traced_like_brute_force() {
    // A flat mesh: unit squares in z = 0, and walls of squares standing in
    // the planes x = 0, 4, 8 — every box flat on some axis.
    let mut boxes = Vec::new();
    for i in 0..12 {
        for j in 0..12 {
            let (x, y) = (f64::from(i), f64::from(j));
            boxes.push(Aabb::new(
                Vec3::new(x, y, 0.0),
                Vec3::new(x + 1.0, y + 1.0, 0.0),
            ));
            if i % 4 == 0 && j < 4 {
                let z = f64::from(j);
                boxes.push(Aabb::new(Vec3::new(x, 0.0, z), Vec3::new(x, 12.0, z + 1.0)));
            }
        }
    }
    let mut rng = Rng::new(13);
    let mut rays = random_rays(&mut rng, 1_500, 6.0);
    for _ in 0..500 {
        // Down onto the floor and across the walls, some exactly in a
        // wall's plane.
        let x = if rng.uniform() < 0.3 {
            f64::from(4 * rng.below(3))
        } else {
            rng.range(-1.0, 13.0)
        };
        let y = rng.range(-1.0, 13.0);
        rays.push(Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z));
        rays.push(Ray::new(Vec3::new(-2.0, y, rng.range(0.0, 4.0)), Vec3::X));
        rays.push(Ray::new(Vec3::new(x, -1.0, rng.range(0.0, 4.0)), Vec3::Y));
    }
    let tree = assert_matches_brute_force(&boxes, &rays, "flat boxes");
    assert!(splits(&tree).len() > 10);
}

/// Unit cubes on every other integer of a lattice, and flat squares on
/// some of their faces: every event, so every split plane, is an integer.
fn lattice() -> Vec<Aabb> {
    let mut boxes = Vec::new();
    for i in 0..6 {
        for j in 0..6 {
            for k in 0..6 {
                let min = 2.0 * Vec3::new(f64::from(i), f64::from(j), f64::from(k));
                boxes.push(Aabb::new(min, min + Vec3::ONE));
                if (i + j + k) % 3 == 0 {
                    let face = Vec3::new(min.x, min.y + 1.0, min.z + 1.0);
                    boxes.push(Aabb::new(min, face));
                }
            }
        }
    }
    boxes
}

#[test]
fn rays_in_on_and_along_split_planes_match_brute_force() {
    let boxes = lattice();
    let mut rng = Rng::new(14);
    let mut rays = Vec::new();
    let coordinate = |rng: &mut Rng| f64::from(rng.below(14)) - 1.0;
    for _ in 0..3_000 {
        let plane_axis = rng.below(3) as usize;
        let along = (plane_axis + 1 + rng.below(2) as usize) % 3;
        let sign = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
        // The origin lies exactly on a plane of `plane_axis` (often a split
        // plane), the other coordinates on a plane or anywhere.
        let mut origin = rng.point_in(Vec3::splat(-1.0), Vec3::splat(12.0));
        origin[plane_axis] = coordinate(&mut rng);
        if rng.uniform() < 0.5 {
            let other = 3 - plane_axis - along;
            origin[other] = coordinate(&mut rng);
        }
        origin[along] = if sign > 0.0 { -2.0 } else { 13.0 };
        // Along the plane, with +0 or -0 across it.
        let mut dir = sign * unit(along);
        dir[plane_axis] = if rng.uniform() < 0.5 { 0.0 } else { -0.0 };
        rays.push(Ray::new(origin, dir));
        // Lying in the plane, slanted.
        let mut slanted = rng.unit_vector();
        slanted[plane_axis] = 0.0;
        rays.push(Ray::new(origin, slanted));
        // Starting on the plane and crossing it.
        let start = rng.point_in(Vec3::splat(-1.0), Vec3::splat(12.0));
        let mut on_plane = start;
        on_plane[plane_axis] = coordinate(&mut rng);
        rays.push(Ray::new(on_plane, rng.unit_vector()));
        rays.push(Ray::new(on_plane, sign * unit(plane_axis)));
    }
    let tree = assert_matches_brute_force(&boxes, &rays, "lattice");
    let planes = splits(&tree);
    assert!(planes.len() > 50);
    assert!(planes.iter().all(|&(_, s)| s == s.round()), "{planes:?}");
}

#[test]
fn ranges_starting_or_ending_on_split_planes_match_brute_force() {
    let boxes = lattice();
    let mut rng = Rng::new(15);
    let mut rays = Vec::new();
    for _ in 0..3_000 {
        // Integer origins, axis-parallel directions and integer ranges:
        // every range ends on a lattice plane.
        let origin = Vec3::new(
            f64::from(rng.below(13)),
            f64::from(rng.below(13)),
            f64::from(rng.below(13)),
        ) - Vec3::splat(0.5 * f64::from(rng.below(2)));
        let axis = rng.below(3) as usize;
        let dir = if rng.uniform() < 0.5 {
            unit(axis)
        } else {
            -unit(axis)
        };
        let mut ray = Ray::segment(origin, dir, f64::from(1 + rng.below(6)));
        ray.t_min = f64::from(rng.below(3));
        rays.push(ray);
        let slanted = Vec3::new(
            f64::from(rng.below(3)) - 1.0,
            f64::from(rng.below(3)) - 1.0,
            1.0,
        );
        rays.push(Ray::segment(origin, slanted, f64::from(1 + rng.below(6))));
    }
    assert_matches_brute_force(&boxes, &rays, "integer ranges");
}

#[test]
fn a_hit_beyond_the_current_cell_waits_for_closer_cells() {
    // A ray along (1, 1, 0) passes a wall whose box it meets only at t = 5;
    // a small box at t = 3 lies in cells it visits after the wall's first.
    let mut rng = Rng::new(16);
    let mut boxes = vec![
        Aabb::new(Vec3::new(5.0, 0.0, -1.0), Vec3::new(6.0, 10.0, 1.0)),
        Aabb::new(Vec3::new(3.0, 3.0, -0.5), Vec3::new(4.0, 4.0, 0.5)),
    ];
    boxes.extend(
        random_boxes(&mut rng, 300, 20.0, 0.3)
            .into_iter()
            .filter(|b| {
                b.intersect_ray(&Ray::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)))
                    .is_none()
            }),
    );
    let ray = Ray::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0));
    assert_matches_brute_force(&boxes, &[ray], "wall and box");
    let tree = Accelerator::build(AccelKind::KdTree, &boxes);
    let t = trace(&tree, &boxes, &ray, RayCoherence::Coherent)
        .0
        .unwrap();
    assert!((t - 3.0).abs() < 1e-12, "{t}");
}

#[test]
fn unplaceable_boxes_are_tested_like_brute_force() {
    let mut rng = Rng::new(17);
    let mut boxes = random_boxes(&mut rng, 200, 5.0, 1.0);
    boxes[3] = Aabb::INFINITE;
    boxes[50] = Aabb::EMPTY;
    boxes[70] = Aabb::new(Vec3::ZERO, Vec3::new(f64::NAN, 1.0, 1.0));
    boxes[90] = Aabb::new(Vec3::ZERO, Vec3::splat(1e40));
    let tree = KdTree::build(&boxes);
    tree.validate(&boxes).unwrap();
    assert_eq!(tree.loose.len(), 4);
    // Brute force offers a primitive to the closure whenever the ray meets
    // its box; let the strange ones report a hit at t = 7 when asked.
    let hit = |i: u32, ray: &Ray, t_max: f64| match i {
        3 | 50 | 70 | 90 => (7.0 < t_max).then_some(7.0),
        _ => box_hit(&boxes[i as usize], ray, t_max),
    };
    let oracle = Accelerator::build(AccelKind::Linear, &boxes);
    let accel = Accelerator::KdTree(tree);
    let rays = random_rays(&mut rng, 500, 5.0);
    assert_agrees_with(&accel, &oracle, &rays, hit);
}

#[test]
fn counters_count_nodes_visited_and_primitives_tested() {
    let mut rng = Rng::new(18);
    let boxes = random_boxes(&mut rng, 1_000, 10.0, 0.5);
    let tree = KdTree::build(&boxes);
    let mut ctx = QueryContext::default();
    let away = Ray::new(Vec3::splat(20.0), Vec3::ONE);
    assert_eq!(tree.intersect(&away, &mut ctx, |_, _| Some(1.0)), None);
    assert_eq!(ctx.counters, TraversalCounters::default());

    let through = Ray::new(Vec3::new(-20.0, 0.1, 0.2), Vec3::X);
    let mut tested = 0;
    tree.intersect(&through, &mut ctx, |i, t_max| {
        tested += 1;
        box_hit(&boxes[i as usize], &through, t_max)
    });
    assert_eq!(ctx.counters.primitives, tested);
    assert!(
        ctx.counters.nodes > 1 && ctx.counters.primitives < 200,
        "{:?}",
        ctx.counters
    );
}

#[test]
fn build_params_bound_the_depth_and_the_cost_model_decides_leaves() {
    let mut rng = Rng::new(19);
    let boxes = random_boxes(&mut rng, 2_000, 50.0, 1.0);
    let shallow = KdTreeBuildParams {
        max_depth: Some(3),
        ..KdTreeBuildParams::default()
    };
    let tree = KdTree::build_with(&boxes, &shallow);
    tree.validate(&boxes).unwrap();
    assert_eq!(tree.stats().max_depth, 3);
    let costly_traversal = KdTreeBuildParams {
        traversal_cost: 1e9,
        ..KdTreeBuildParams::default()
    };
    let leaf = KdTree::build_with(&boxes, &costly_traversal).stats();
    assert_eq!((leaf.nodes, leaf.references), (1, 2_000));
    assert_eq!(leaf.sah_cost, 2_000.0);
}

#[test]
fn trees_deeper_than_the_short_stack_are_walked_like_brute_force() {
    // Cubes halving towards the origin, each cut off by its own planes: a
    // chain of splits deeper than the short stack holds.
    let boxes: Vec<Aabb> = (0..60)
        .map(|i| {
            let s = 0.5f64.powi(i);
            Aabb::new(Vec3::splat(s), Vec3::splat(1.5 * s))
        })
        .collect();
    let deep = KdTreeBuildParams {
        max_depth: Some(STACK_CAPACITY),
        ..KdTreeBuildParams::default()
    };
    let tree = KdTree::build_with(&boxes, &deep);
    tree.validate(&boxes).unwrap();
    assert!(tree.max_depth > SHALLOW, "depth {}", tree.max_depth);
    assert_eq!(tree.max_depth, tree.stats().max_depth);
    let accel = Accelerator::KdTree(tree);
    let oracle = Accelerator::build(AccelKind::Linear, &boxes);
    let mut rng = Rng::new(23);
    let rays: Vec<Ray> = (0..2_000)
        .flat_map(|i| {
            // From far away towards the cubes, and out from among them.
            let origin = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            let target = Vec3::splat(1.25 * 0.5f64.powi(i % 60));
            [
                Ray::new(origin, target - origin),
                Ray::new(target * 0.9, origin - target),
            ]
        })
        .collect();
    with_either_start(|start, coherence| {
        for ray in &rays {
            assert_eq!(
                trace(&accel, &boxes, ray, coherence),
                trace(&oracle, &boxes, ray, coherence),
                "{start}: {ray:?}"
            );
        }
    });
}

#[test]
fn validate_finds_a_tree_deeper_than_it_states() {
    let mut rng = Rng::new(24);
    let boxes = random_boxes(&mut rng, 500, 20.0, 1.0);
    let mut tree = KdTree::build(&boxes);
    assert!(tree.validate(&boxes).is_ok());
    tree.max_depth -= 1;
    let why = tree.validate(&boxes).unwrap_err();
    assert!(why.contains("beyond the tree's stated"), "{why}");
    tree.max_depth = STACK_CAPACITY + 1;
    let why = tree.validate(&boxes).unwrap_err();
    assert!(why.contains("beyond the stack's"), "{why}");
}

/// Random triangles on a coarse grid, so many lie flat in or touch split
/// planes at a vertex or an edge, with thin slivers and large diagonal
/// ones that cross many cells.
fn awkward_triangles(rng: &mut Rng, n: usize) -> Vec<Triangle> {
    let mut triangles = Vec::new();
    while triangles.len() < n {
        let base = Vec3::from_array([0; 3].map(|_| f64::from(rng.below(16))));
        let corner = |rng: &mut Rng, size: u32| {
            base + Vec3::from_array([0; 3].map(|_| f64::from(rng.below(size)) * 0.5))
        };
        let (a, b, mut c) = match rng.below(3) {
            0 => (corner(rng, 24), corner(rng, 24), corner(rng, 24)),
            1 => (corner(rng, 4), corner(rng, 4), corner(rng, 4)),
            // A sliver: the third corner barely off the first edge.
            _ => {
                let (a, b) = (corner(rng, 12), corner(rng, 12));
                (a, b, a + (b - a) * 0.375 + Vec3::splat(1e-7))
            }
        };
        // A quarter lie in a grid plane.
        if rng.below(4) == 3 {
            let axis = rng.below(3) as usize;
            c[axis] = a[axis];
            let mut b2 = b;
            b2[axis] = a[axis];
            if let Ok(t) = Triangle::new(a, b2, c) {
                triangles.push(t);
            }
        } else if let Ok(t) = Triangle::new(a, b, c) {
            triangles.push(t);
        }
    }
    triangles
}

#[test]
fn perfect_splits_keep_every_triangle_where_it_meets_a_cell_and_match_brute_force() {
    let mut rng = Rng::new(23);
    let triangles = awkward_triangles(&mut rng, 1_500);
    let boxes: Vec<Aabb> = triangles.iter().map(Triangle::bounds).collect();
    let clip =
        |i: u32, cell: &Aabb| clipped_triangle_bounds(triangles[i as usize].vertices(), cell);
    let tree = KdTree::build_clipped(&boxes, &KdTreeBuildParams::default(), &clip);
    tree.validate_clipped(&boxes, &clip).unwrap();
    // Clipping must pay: fewer references than clipping the boxes.
    let plain = KdTree::build(&boxes).stats().references;
    let clipped = tree.stats().references;
    assert!(
        clipped < plain,
        "{clipped} references, {plain} without clipping"
    );

    // Rays at the corners and along the edges (on the grid, so often in
    // split planes), axis-parallel and random.
    let mut rays = random_rays(&mut rng, 2_000, 20.0);
    for t in triangles.iter().take(500) {
        let [a, b, c] = t.vertices();
        let origin = rng.point_in(Vec3::splat(-10.0), Vec3::splat(40.0));
        for target in [a, b, c, (a + b) * 0.5, (b + c) * 0.25 + c * 0.5] {
            rays.push(Ray::new(origin, target - origin));
            let axis = rng.below(3) as usize;
            let mut dir = Vec3::ZERO;
            dir[axis] = 1.0;
            rays.push(Ray::new(target - dir * 50.0, dir));
        }
    }
    let hit = |i: u32, ray: &Ray, t_max: f64| {
        let mut r = *ray;
        r.t_max = t_max;
        triangles[i as usize].intersect(&r).map(|h| h.t)
    };
    let oracle = Accelerator::build(AccelKind::Linear, &boxes);
    let accel = Accelerator::KdTree(tree);
    let hits = assert_agrees_with(&accel, &oracle, &rays, hit);
    assert!(
        hits > rays.len() / 4,
        "only {hits} of {} rays hit",
        rays.len()
    );
}
