//! CSG against a brute-force reference: random trees of random solids,
//! classified along random rays by sampling points and asking each child's
//! own inside test; coincident surfaces; materials; refraction through a
//! lens made of two spheres; and every acceleration structure over CSG
//! objects against brute force.

use super::*;
use crate::accel::AccelKind;
use crate::math::random::Rng;
use crate::math::{Transform, offset_ray_origin};
use crate::shape::small_mesh::tests::{cube_mesh, torus_mesh};
use crate::shape::testing::{assert_crossings_alternate, assert_no_self_intersection};
use crate::shape::{AxisBox, Cone, Cylinder, Plane, SmallMesh, Sphere, Torus};
use crate::world::{MaterialId, Objects, World};

/// A CSG tree as written, for the reference: evaluated as given, not as
/// [`Csg`] flattens it.
enum Spec {
    Leaf(Box<(Shape, Option<Transform>)>),
    Op(CsgOperation, Vec<Spec>),
}

impl Spec {
    fn inside(&self, p: Vec3) -> bool {
        match self {
            Spec::Leaf(leaf) => {
                let (shape, t) = &**leaf;
                shape.contains(t.map_or(p, |t| t.object_from_world().transform_point3(p)))
            }
            Spec::Op(op, children) => {
                let first = children[0].inside(p);
                let rest = children[1..].iter().map(|c| c.inside(p));
                match op {
                    CsgOperation::Union => first || rest.into_iter().any(|i| i),
                    CsgOperation::Intersection => first && rest.into_iter().all(|i| i),
                    CsgOperation::Difference => first && !rest.into_iter().any(|i| i),
                }
            }
        }
    }

    fn child(&self) -> CsgChild {
        match self {
            Spec::Leaf(leaf) => CsgChild {
                shape: leaf.0.clone(),
                transform: leaf.1,
                material: None,
            },
            Spec::Op(..) => CsgChild {
                shape: self.build(),
                transform: None,
                material: None,
            },
        }
    }

    fn build(&self) -> Shape {
        let Spec::Op(op, children) = self else {
            unreachable!("a leaf is not built alone")
        };
        Shape::Csg(Csg::new(*op, children.iter().map(Spec::child).collect()).unwrap())
    }
}

fn random_leaf(rng: &mut Rng) -> Spec {
    let shape = match rng.below(6) {
        5 => Shape::Mesh(torus_mesh(rng.range(0.4, 0.8), rng.range(0.1, 0.35), 10, 6)),
        0 => Shape::Sphere(
            Sphere::new(
                rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5)),
                rng.range(0.4, 1.0),
            )
            .unwrap(),
        ),
        1 => {
            let a = rng.point_in(Vec3::splat(-1.0), Vec3::splat(0.0));
            let b = a + rng.point_in(Vec3::splat(0.3), Vec3::splat(1.5));
            Shape::AxisBox(AxisBox::new(a, b).unwrap())
        }
        2 => {
            Shape::Cylinder(Cylinder::new(rng.range(0.2, 0.7), rng.range(0.5, 1.5), true).unwrap())
        }
        3 => Shape::Cone(
            Cone::new(
                rng.range(0.0, 0.7),
                rng.range(0.2, 0.7),
                rng.range(0.5, 1.5),
                true,
            )
            .unwrap(),
        ),
        _ => Shape::Torus(Torus::new(rng.range(0.4, 0.8), rng.range(0.1, 0.35)).unwrap()),
    };
    let transform = (rng.below(2) == 0).then(|| {
        Transform::translate(rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5)))
            .unwrap()
            .then_after(&Transform::rotate(rng.unit_vector(), rng.range(0.0, 360.0)).unwrap())
            .then_after(
                &Transform::scale(rng.point_in(Vec3::splat(0.6), Vec3::splat(1.4))).unwrap(),
            )
    });
    Spec::Leaf(Box::new((shape, transform)))
}

fn random_spec(rng: &mut Rng, op: CsgOperation, depth: u32) -> Spec {
    let count = 2 + rng.below(2) as usize;
    let children = (0..count)
        .map(|_| {
            if depth > 0 && rng.below(3) == 0 {
                let op = [
                    CsgOperation::Union,
                    CsgOperation::Intersection,
                    CsgOperation::Difference,
                ][rng.below(3) as usize];
                random_spec(rng, op, depth - 1)
            } else {
                random_leaf(rng)
            }
        })
        .collect();
    Spec::Op(op, children)
}

/// The ray's first change of inside-ness by sampling `spec` at `n`
/// points over `(0, length)`: the interval `(t_before, t_after]` it lies
/// in, or `None`.
fn first_change(spec: &Spec, ray: &Ray, length: f64, n: usize) -> Option<(f64, f64)> {
    let t = |k: usize| length * (k as f64 + 0.5) / n as f64;
    let start = spec.inside(ray.at(t(0)));
    (1..n)
        .find(|&k| spec.inside(ray.at(t(k))) != start)
        .map(|k| (t(k - 1), t(k)))
}

#[test]
fn every_operation_finds_the_first_boundary_that_point_sampling_finds() {
    let mut rng = Rng::new(18);
    for op in [
        CsgOperation::Union,
        CsgOperation::Intersection,
        CsgOperation::Difference,
    ] {
        let (mut hits, mut rays, mut normals_out) = (0, 0, 0);
        for _ in 0..40 {
            let spec = random_spec(&mut rng, op, 1);
            let shape = spec.build();
            let bounds = shape.bounds();
            if bounds.is_empty() {
                continue;
            }
            let size = bounds.extent().length();
            let delta = 1e-7 * size;
            for i in 0..60 {
                let origin = if i % 3 == 0 {
                    rng.point_in(bounds.min, bounds.max)
                } else {
                    bounds.centroid() + 2.0 * size * rng.unit_vector()
                };
                let target = rng.point_in(bounds.min, bounds.max);
                let dir = (target - origin).normalize();
                let ray = Ray::new(origin, dir);
                let length = 4.0 * size;
                let n = 4000;
                let step = length / n as f64;
                let sampled = first_change(&spec, &ray, length, n);
                rays += 1;
                let Some(hit) = shape.intersect(&ray) else {
                    assert!(
                        sampled.is_none(),
                        "{op:?}: missed a boundary in {sampled:?}"
                    );
                    continue;
                };
                hits += 1;
                let t = hit.t;
                let before = spec.inside(ray.at(t - delta));
                assert_ne!(
                    before,
                    spec.inside(ray.at(t + delta)),
                    "{op:?}: no boundary at {t}"
                );
                // Not beyond the first change sampling sees; before it only
                // into a feature thinner than the step, left again unseen,
                // so from the state sampling starts in.
                let start = spec.inside(ray.at(step / 2.0));
                if let Some((lo, hi)) = sampled {
                    assert!(
                        t <= hi + delta,
                        "{op:?}: hit at {t}, sampling changes in ({lo}, {hi}]"
                    );
                }
                if sampled.is_none_or(|(lo, _)| t <= lo - delta) {
                    assert!(t < step || before == start, "{op:?}: hit at {t}");
                }
                // The normal points out of the result, against the ray
                // where it enters.
                let s = shape.surface(&ray, &hit);
                assert!((s.point - ray.at(t)).length() < 1e-9 * size);
                assert_eq!(s.normal.dot(dir) < 0.0, !before, "{op:?}: at {t}");
                let out = spec.inside(s.point + 1e-6 * size * s.normal);
                let inward = spec.inside(s.point - 1e-6 * size * s.normal);
                normals_out += usize::from(!out && inward);
            }
        }
        assert!(hits > rays / 4, "{op:?}: {hits} of {rays}");
        // Near a child's edge the step off the surface may land elsewhere.
        assert!(
            normals_out * 100 > hits * 98,
            "{op:?}: {normals_out} of {hits}"
        );
    }
}

#[test]
fn crossings_of_a_csg_object_agree_with_its_inside_test() {
    let mut rng = Rng::new(81);
    for _ in 0..20 {
        let spec = random_spec(&mut rng, CsgOperation::Difference, 1);
        let shape = spec.build();
        let bounds = shape.bounds();
        let size = bounds.extent().length();
        for _ in 0..40 {
            let origin = bounds.centroid() + 2.0 * size * rng.unit_vector();
            let ray = Ray::new(origin, rng.point_in(bounds.min, bounds.max) - origin);
            let mut crossings = Crossings::new();
            shape.crossings(&ray, &mut crossings);
            assert!(crossings.windows(2).all(|w| w[0].entering != w[1].entering));
            for c in &crossings {
                let p = ray.at(c.hit.t);
                let d = 1e-7 * size * ray.dir.normalize();
                assert_eq!(shape.contains(p + d), c.entering);
                assert_eq!(shape.contains(p + d), spec.inside(p + d));
            }
        }
    }
}

fn unit_box() -> Shape {
    Shape::AxisBox(AxisBox::new(Vec3::ZERO, Vec3::ONE).unwrap())
}

fn child(shape: Shape, transform: Option<Transform>) -> CsgChild {
    CsgChild {
        shape,
        transform,
        material: None,
    }
}

#[test]
fn a_cutter_sharing_a_face_with_the_base_leaves_no_speckles() {
    // A pocket in the top of the unit box, 0.3 deep, its cutter's top face
    // on the box's top face; the cutter once as a box in place, once as a
    // unit box moved and scaled into place, and once rotated a quarter
    // turn, so rounding puts its face above, on or below the base's.
    let pocket = Vec3::new(0.3, 0.3, 0.7);
    let cutters = [
        child(
            Shape::AxisBox(AxisBox::new(pocket, Vec3::new(0.7, 0.7, 1.0)).unwrap()),
            None,
        ),
        child(
            unit_box(),
            Some(
                Transform::translate(pocket)
                    .unwrap()
                    .then_after(&Transform::scale(Vec3::new(0.4, 0.4, 0.3)).unwrap()),
            ),
        ),
        child(
            unit_box(),
            Some(
                Transform::translate(Vec3::new(0.7, 0.3, 0.7))
                    .unwrap()
                    .then_after(&Transform::rotate(Vec3::Z, 90.0).unwrap())
                    .then_after(&Transform::scale(Vec3::new(0.4, 0.4, 0.3)).unwrap()),
            ),
        ),
    ];
    let mut rng = Rng::new(3);
    for cutter in cutters {
        let shape = Shape::Csg(
            Csg::new(
                CsgOperation::Difference,
                vec![child(unit_box(), None), cutter],
            )
            .unwrap(),
        );
        for _ in 0..2000 {
            let at = rng.point_in(Vec3::new(0.31, 0.31, 2.0), Vec3::new(0.69, 0.69, 2.0));
            let tilt = rng.point_in(
                Vec3::new(-0.005, -0.005, -1.0),
                Vec3::new(0.005, 0.005, -1.0),
            );
            let hit = shape.intersect(&Ray::new(at, tilt)).unwrap();
            let ray = Ray::new(at, tilt);
            let z = ray.at(hit.t).z;
            assert!((z - 0.7).abs() < 1e-9, "hit the cut-away face at z = {z}");
            assert!(shape.surface(&ray, &hit).normal.z > 0.99);
        }
    }
}

#[test]
fn coincident_faces_join_or_cancel_and_the_first_child_wins_ties() {
    // Two boxes stacked face to face are one solid: a ray along x through
    // both crosses its surface twice, never at the shared face.
    let upper = Transform::translate(Vec3::new(1.0, 0.0, 0.0)).unwrap();
    let stacked = Shape::Csg(
        Csg::new(
            CsgOperation::Union,
            vec![child(unit_box(), None), child(unit_box(), Some(upper))],
        )
        .unwrap(),
    );
    let mut rng = Rng::new(4);
    for _ in 0..500 {
        let origin = Vec3::new(-1.0, rng.range(0.01, 0.99), rng.range(0.01, 0.99));
        let ray = Ray::new(origin, Vec3::new(1.0, rng.range(-1e-3, 1e-3), 0.0));
        let mut crossings = Crossings::new();
        stacked.crossings(&ray, &mut crossings);
        assert_eq!(crossings.len(), 2, "{crossings:?}");
        assert!((ray.at(crossings[1].hit.t).x - 2.0).abs() < 1e-9);
    }
    // A box minus itself is empty; a box intersected with itself is the
    // box, its faces the first child's.
    let same = |op| Csg::new(op, vec![child(unit_box(), None), child(unit_box(), None)]).unwrap();
    let ray = Ray::new(Vec3::new(0.5, 0.5, 3.0), -Vec3::Z);
    assert_eq!(same(CsgOperation::Difference).intersect(&ray), None);
    let hit = same(CsgOperation::Intersection).intersect(&ray).unwrap();
    assert_eq!((hit.t, hit.part >> 16), (2.0, 0));
    let hit = same(CsgOperation::Union).intersect(&ray).unwrap();
    assert_eq!((hit.t, hit.part >> 16), (2.0, 0));
}

#[test]
fn open_children_and_lone_children_are_refused() {
    let plane = Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap());
    let open_cylinder = Shape::Cylinder(Cylinder::new(1.0, 1.0, false).unwrap());
    assert_eq!(
        Csg::new(
            CsgOperation::Union,
            vec![child(unit_box(), None), child(plane, None)]
        )
        .unwrap_err()
        .to_string(),
        "child 1 (plane) is not a closed solid: a plane is a surface with no inside"
    );
    assert_eq!(
        Csg::new(
            CsgOperation::Difference,
            vec![child(open_cylinder, None), child(unit_box(), None)]
        )
        .unwrap_err()
        .to_string(),
        "child 0 (cylinder) is not a closed solid: with `caps = false` its ends are open"
    );
    assert_eq!(
        Csg::new(CsgOperation::Intersection, vec![child(unit_box(), None)])
            .unwrap_err()
            .to_string(),
        "a intersection needs at least two children, got 1"
    );
}

#[test]
fn children_keep_their_materials_and_others_take_their_parents() {
    // (box [red] ∪ (sphere ∪ sphere [blue]) [green]): the first sphere
    // takes the inner union's green, the outer object's material is for
    // no leaf here.
    let sphere = |x: f64| Shape::Sphere(Sphere::new(Vec3::new(x, 0.5, 0.5), 0.4).unwrap());
    let inner = Csg::new(
        CsgOperation::Union,
        vec![
            child(sphere(3.0), None),
            CsgChild {
                material: Some(2),
                ..child(sphere(5.0), None)
            },
        ],
    )
    .unwrap();
    let csg = Csg::new(
        CsgOperation::Union,
        vec![
            CsgChild {
                material: Some(1),
                ..child(unit_box(), None)
            },
            CsgChild {
                material: Some(3),
                ..child(Shape::Csg(inner), None)
            },
            child(sphere(7.0), None),
        ],
    )
    .unwrap();
    assert_eq!(csg.leaf_count(), 4);
    let mut objects = Objects::default();
    objects.add_primitive(Shape::Csg(csg), MaterialId(9), Transform::IDENTITY);
    let world = World::new(&objects);
    for (x, material) in [(0.5, 1), (3.0, 3), (5.0, 2), (7.0, 9)] {
        let ray = Ray::new(Vec3::new(x, 0.5, 5.0), -Vec3::Z);
        let hit = world.intersect(&ray).unwrap();
        assert_eq!(
            world.surface(&ray, &hit).material,
            MaterialId(material),
            "{x}"
        );
    }
}

/// A biconvex lens of radius `r` and thickness `d` on the z axis, centred
/// at the origin: the intersection of two spheres.
fn lens(r: f64, d: f64) -> Shape {
    let sphere = |z: f64| Shape::Sphere(Sphere::new(Vec3::new(0.0, 0.0, z), r).unwrap());
    let c = r - d / 2.0;
    Shape::Csg(
        Csg::new(
            CsgOperation::Intersection,
            vec![child(sphere(c), None), child(sphere(-c), None)],
        )
        .unwrap(),
    )
}

/// A leaf as a child again, with its transform and material.
fn leaf_child(leaf: &Leaf) -> CsgChild {
    CsgChild {
        shape: leaf.shape.clone(),
        transform: leaf.transform,
        material: leaf.material,
    }
}

/// A hollow shell: a sphere minus a smaller one inside it.
fn shell() -> Shape {
    let sphere = |r: f64| Shape::Sphere(Sphere::new(Vec3::ZERO, r).unwrap());
    Shape::Csg(
        Csg::new(
            CsgOperation::Difference,
            vec![child(sphere(1.0), None), child(sphere(0.8), None)],
        )
        .unwrap(),
    )
}

#[test]
fn rays_walking_through_csg_objects_enter_and_leave_alternately() {
    // The medium stack's rule: walking from offset origin to offset
    // origin, a ray through a shell crosses four surfaces, in, out, in,
    // out, and never meets the surface it left.
    let ray = Ray::new(Vec3::new(-3.0, 0.01, 0.02), Vec3::new(1.0, 0.01, 0.0));
    assert_eq!(assert_crossings_alternate(&shell(), ray), 4);
    assert_eq!(assert_crossings_alternate(&lens(2.0, 0.5), ray), 2);
    assert_no_self_intersection(&shell(), 5);
    assert_no_self_intersection(&lens(2.0, 0.5), 6);
}

#[test]
fn a_lens_of_two_spheres_focuses_where_the_thick_lens_equation_says() {
    // Paraxial rays parallel to the axis, refracted by Snell's law at the
    // surfaces the world reports (normals turned towards the incoming
    // side), cross the axis at the back focal distance from the back
    // vertex: 1/f = (n-1) (1/R1 - 1/R2 + (n-1) d / (n R1 R2)) with
    // R1 = R, R2 = -R, and BFD = f (1 - (n-1) d / (n R1)).
    use crate::shading::optics::refract;
    //
    // The two spheres have materials of their own (1 and 2, both of index
    // `n`) and the lens is filled with material 3 (index `n`): a ray walks
    // through it with the medium stack, keyed by the lens's medium.
    use crate::shading::MediumStack;
    let (r, d, n) = (2.0, 0.6, 1.5);
    let ior = [1.0, n, n, n];
    let Shape::Csg(two_materials) = lens(r, d) else {
        unreachable!()
    };
    let mut children: Vec<CsgChild> = two_materials.data.leaves.iter().map(leaf_child).collect();
    children[0].material = Some(1);
    children[1].material = Some(2);
    let lens = Csg::new(CsgOperation::Intersection, children)
        .unwrap()
        .filled_with(Some(3));
    let mut objects = Objects::default();
    objects.add_primitive(Shape::Csg(lens), MaterialId(0), Transform::IDENTITY);
    let world = World::new(&objects);
    let f = 1.0 / ((n - 1.0) * (2.0 / r - (n - 1.0) * d / (n * r * r)));
    let bfd = f * (1.0 - (n - 1.0) * d / (n * r));
    for h in [0.005, 0.01, 0.02] {
        let mut ray = Ray::new(Vec3::new(h, 0.0, -5.0), Vec3::Z);
        let mut inside = false;
        let mut media = MediumStack::default();
        for material in [1, 2] {
            let hit = world.intersect(&ray).expect("the lens is crossed twice");
            let s = world.surface(&ray, &hit);
            assert_eq!(s.material, MaterialId(material));
            assert_eq!(s.medium, MaterialId(3));
            let entering = ray.dir.dot(s.normal) < 0.0;
            assert_ne!(entering, inside);
            let crossing = media.cross(s.medium, ior[s.medium.0 as usize], entering);
            let facing = if entering { s.normal } else { -s.normal };
            let eta = crossing.n_from / crossing.n_to;
            let dir = refract(ray.dir.normalize(), facing, eta).unwrap();
            let origin = offset_ray_origin(s.point, s.point_error, s.normal, dir);
            ray = Ray::new(origin, dir);
            inside = entering;
            media = crossing.after();
        }
        // Out in the air again, the stack empty.
        assert_eq!(media.ior(), 1.0);
        assert!(!media.contains(MaterialId(3)));
        assert!(world.intersect(&ray).is_none());
        let t = -ray.origin.x / ray.dir.x;
        let crossing = ray.at(t).z - d / 2.0;
        let efl = h / (-ray.dir.x / ray.dir.z);
        assert!(
            (crossing / bfd - 1.0).abs() < 0.01,
            "h = {h}: {crossing} vs {bfd}"
        );
        assert!((efl / f - 1.0).abs() < 0.01, "h = {h}: {efl} vs {f}");
    }
}

#[test]
fn every_structure_agrees_with_brute_force_on_csg_objects() {
    let mut rng = Rng::new(77);
    let mut objects = Objects::default();
    for i in 0..24 {
        let op = [
            CsgOperation::Union,
            CsgOperation::Intersection,
            CsgOperation::Difference,
        ][i % 3];
        let shape = random_spec(&mut rng, op, 1).build();
        if shape.bounds().is_empty() {
            continue;
        }
        let at = rng.point_in(Vec3::splat(-6.0), Vec3::splat(6.0));
        let place = Transform::translate(at)
            .unwrap()
            .then_after(&Transform::rotate(rng.unit_vector(), rng.range(0.0, 360.0)).unwrap());
        objects.add_primitive(shape, MaterialId(0), place);
        let sphere = Sphere::new(rng.point_in(Vec3::splat(-6.0), Vec3::splat(6.0)), 0.5).unwrap();
        objects.add_primitive(Shape::Sphere(sphere), MaterialId(0), Transform::IDENTITY);
    }
    let oracle = World::build(&objects, AccelKind::Linear);
    let rays: Vec<Ray> = (0..1500)
        .map(|i| {
            let origin = rng.point_in(Vec3::splat(-9.0), Vec3::splat(9.0));
            let target = rng.point_in(Vec3::splat(-6.0), Vec3::splat(6.0));
            if i % 2 == 0 {
                Ray::new(origin, target - origin)
            } else {
                Ray::segment(origin, target - origin, rng.range(0.2, 1.0))
            }
        })
        .collect();
    for kind in AccelKind::ALL {
        let world = World::build(&objects, kind);
        let mut csg_hits = 0;
        for ray in &rays {
            let expected = oracle.intersect(ray);
            assert_eq!(world.intersect(ray), expected, "{kind:?} {ray:?}");
            assert_eq!(world.occluded(ray), expected.is_some(), "{kind:?}");
            if let Some(hit) = expected {
                let s = world.surface(ray, &hit);
                assert!((s.point - ray.at(hit.t())).length() < 1e-9, "{kind:?}");
                csg_hits += usize::from(hit.primitive.0 % 2 == 0);
            }
        }
        assert!(csg_hits > 120, "{kind:?}: {csg_hits}");
    }
}

#[test]
fn a_ray_through_children_of_different_materials_leaves_in_the_outside_medium() {
    // Two overlapping spheres of glasses 1 and 2 (indices 1.5 and 1.7),
    // their union filled with glass 1: in through sphere 1, out through
    // sphere 2, the ray is back in the air (keyed by the surface's
    // material, the stack would still hold glass 1).
    use crate::shading::MediumStack;
    let ior = [1.0, 1.5, 1.7];
    let sphere = |x: f64, material| CsgChild {
        material: Some(material),
        ..child(
            Shape::Sphere(Sphere::new(Vec3::new(x, 0.0, 0.0), 1.0).unwrap()),
            None,
        )
    };
    let union = Csg::new(CsgOperation::Union, vec![sphere(-0.5, 1), sphere(0.5, 2)]).unwrap();
    let mut objects = Objects::default();
    let glass = union.first_material();
    objects.add_primitive(
        Shape::Csg(union.filled_with(glass)),
        MaterialId(0),
        Transform::IDENTITY,
    );
    let world = World::new(&objects);
    let mut ray = Ray::new(Vec3::new(-5.0, 0.01, 0.02), Vec3::X);
    let mut media = MediumStack::default();
    for (material, entering) in [(1, true), (2, false)] {
        let hit = world.intersect(&ray).unwrap();
        let s = world.surface(&ray, &hit);
        assert_eq!(s.material, MaterialId(material));
        assert_eq!(ray.dir.dot(s.normal) < 0.0, entering);
        let crossing = media.cross(s.medium, ior[s.medium.0 as usize], entering);
        assert_eq!(crossing.n_from, if entering { 1.0 } else { 1.5 });
        assert_eq!(crossing.n_to, if entering { 1.5 } else { 1.0 });
        media = crossing.after();
        ray = Ray::new(
            offset_ray_origin(s.point, s.point_error, s.normal, ray.dir),
            ray.dir,
        );
    }
    assert_eq!(media.ior(), 1.0);
    assert!(world.intersect(&ray).is_none());
}

#[test]
fn a_closed_mesh_child_cuts_like_the_solid_it_meshes() {
    // The cube [-1, 1]³ as a mesh of 12 triangles (given inside out, so
    // turned round) and as a box, each minus a sphere on a corner and
    // intersected with a torus: the same first hits and normals.
    let sphere = || {
        child(
            Shape::Sphere(Sphere::new(Vec3::splat(1.0), 0.8).unwrap()),
            None,
        )
    };
    let torus = || {
        let t = Transform::rotate(Vec3::X, 30.0).unwrap();
        child(Shape::Torus(Torus::new(0.9, 0.5).unwrap()), Some(t))
    };
    let cube_box = Shape::AxisBox(AxisBox::new(Vec3::splat(-1.0), Vec3::ONE).unwrap());
    let build = |cube: Shape| {
        let cut = Csg::new(CsgOperation::Difference, vec![child(cube, None), sphere()]).unwrap();
        let cut = child(Shape::Csg(cut), None);
        Shape::Csg(Csg::new(CsgOperation::Union, vec![cut, torus()]).unwrap())
    };
    let (mesh, reference) = (build(Shape::Mesh(cube_mesh(true))), build(cube_box));
    let mut rng = Rng::new(4);
    let mut on_mesh = 0;
    for _ in 0..2000 {
        let origin = 4.0 * rng.unit_vector();
        let ray = Ray::new(
            origin,
            rng.point_in(Vec3::splat(-1.2), Vec3::splat(1.2)) - origin,
        );
        let (a, b) = (mesh.intersect(&ray), reference.intersect(&ray));
        assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
        let (Some(a), Some(b)) = (a, b) else { continue };
        assert!((a.t - b.t).abs() < 1e-9, "{ray:?}: {} vs {}", a.t, b.t);
        let (sa, sb) = (mesh.surface(&ray, &a), reference.surface(&ray, &b));
        assert!((sa.normal - sb.normal).length() < 1e-9, "{ray:?}");
        on_mesh += usize::from(a.part >> 16 == 0);
    }
    assert!(on_mesh > 300, "{on_mesh}");
}

#[test]
fn an_open_mesh_child_is_refused() {
    let cube = cube_mesh(false);
    let mut triangles = cube.triangles().to_vec();
    triangles.pop();
    let open = SmallMesh::new(cube.positions().to_vec(), triangles).unwrap();
    let error = Csg::new(
        CsgOperation::Union,
        vec![child(Shape::Mesh(open), None), unit_box_child()],
    )
    .unwrap_err();
    assert!(
        matches!(
            error,
            CsgError::Open {
                index: 0,
                kind: "mesh",
                ..
            }
        ),
        "{error}"
    );
}

fn unit_box_child() -> CsgChild {
    child(unit_box(), None)
}
