//! Instances against their flattened copies: a scene of definitions (shapes,
//! meshes, an unbounded plane, instances of instances, a material override)
//! placed with rotations, non-uniform scales and translations, and the same
//! scene with every instance replaced by copies under the composed
//! transforms. Through every structure, and every pair of top and bottom
//! structures, each camera ray and each random ray must find the same
//! hit or miss, the same primitive (numbered as if flattened), the same
//! material, and depth and normal within 1e-6 relative; the flattened copy
//! through brute force (`linear`) is the oracle.

use whitted::accel::AccelKind;
use whitted::math::random::Rng;
use whitted::math::{Ray, Transform, Vec3};
use whitted::mesh::TriangleMesh;
use whitted::render::Camera;
use whitted::shape::{AxisBox, Cylinder, Plane, Shape, Sphere, Triangle};
use whitted::world::{MaterialId, Objects, World};

/// A primitive of the flattened scene, in the instanced numbering's order.
#[derive(Clone, Copy)]
enum Flat {
    /// Shape `i` of the flattened objects.
    Shape(usize),
    /// Triangle `t` of mesh instance `k` of the flattened objects.
    Triangle(usize, usize),
}

/// Adds `level` (the world or a definition) to `flat` under `outer`, every
/// material replaced by `material` if given, recording each primitive in
/// the order the instanced world numbers them.
fn flatten(
    world: &Objects,
    level: &Objects,
    outer: Transform,
    material: Option<MaterialId>,
    flat: &mut Objects,
    order: &mut Vec<Flat>,
) {
    let under = |t: Option<&Transform>| t.map_or(outer, |t| outer.then_after(t));
    for p in &level.primitives {
        let t = under(level.transform(p.transform));
        order.push(Flat::Shape(flat.primitives.len()));
        flat.add_primitive(p.shape.clone(), material.unwrap_or(p.material), t);
    }
    for m in &level.mesh_instances {
        let t = under(level.transform(m.transform));
        let mesh = flat.add_mesh(level.meshes[m.mesh.0 as usize].clone());
        let k = flat.mesh_instances.len();
        flat.add_mesh_instance(mesh, material.unwrap_or(m.material), t);
        order.extend((0..flat.meshes[mesh.0 as usize].len()).map(|t| Flat::Triangle(k, t)));
    }
    for i in &level.instances {
        let t = under(level.transform(i.transform));
        let definition = &world.definitions[i.definition.0 as usize];
        flatten(world, definition, t, material.or(i.material), flat, order);
    }
}

/// The flattened objects and, for each instanced primitive number, the
/// flattened one.
fn flattened(world: &Objects) -> (Objects, Vec<u32>) {
    let mut flat = Objects::default();
    let mut order = Vec::new();
    flatten(
        world,
        world,
        Transform::IDENTITY,
        None,
        &mut flat,
        &mut order,
    );
    let shapes = flat.primitives.len();
    let mut first = Vec::new();
    let mut next = shapes;
    for m in &flat.mesh_instances {
        first.push(next);
        next += flat.meshes[m.mesh.0 as usize].len();
    }
    let numbers = order
        .iter()
        .map(|f| match *f {
            Flat::Shape(i) => i as u32,
            Flat::Triangle(k, t) => (first[k] + t) as u32,
        })
        .collect();
    (flat, numbers)
}

fn soup(rng: &mut Rng, triangles: u32) -> TriangleMesh {
    let positions: Vec<Vec3> = (0..3 * triangles)
        .map(|_| rng.point_in(Vec3::splat(-0.5), Vec3::splat(0.5)))
        .collect();
    let faces = (0..triangles)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    TriangleMesh::new(positions, faces).unwrap()
}

/// Turned about `axis` by `angle`, scaled by `scale`, then moved to `at`.
fn placed(at: Vec3, axis: Vec3, angle: f64, scale: Vec3) -> Transform {
    Transform::translate(at)
        .unwrap()
        .then_after(&Transform::rotate(axis, angle).unwrap())
        .then_after(&Transform::scale(scale).unwrap())
}

/// A forest of trees of leaves, meshes alone, a ground plane inside an
/// instance, and a few objects placed by the world itself.
fn forest() -> Objects {
    let mut rng = Rng::new(18);
    let (bark, leafy, gold) = (MaterialId(0), MaterialId(1), MaterialId(2));
    let mut world = Objects::default();

    let mut leaf = Objects::default();
    let ball = Sphere::new(Vec3::new(0.0, 0.3, 0.0), 0.25).unwrap();
    leaf.add_primitive(Shape::Sphere(ball), leafy, Transform::IDENTITY);
    let tri = Triangle::new(
        Vec3::ZERO,
        Vec3::new(0.4, 0.1, 0.0),
        Vec3::new(0.1, 0.5, 0.2),
    );
    let tilted = Transform::rotate(Vec3::X, 30.0).unwrap();
    leaf.add_primitive(Shape::Triangle(tri.unwrap()), leafy, tilted);
    let mesh = leaf.add_mesh(soup(&mut rng, 40));
    let squashed = placed(
        Vec3::new(0.0, 0.6, 0.0),
        Vec3::Y,
        20.0,
        Vec3::new(0.6, 0.3, 0.6),
    );
    leaf.add_mesh_instance(mesh, leafy, squashed);
    let leaf = world.add_definition(leaf);

    let mut tree = Objects::default();
    let trunk = Cylinder::new(0.1, 1.5, true).unwrap();
    tree.add_primitive(Shape::Cylinder(trunk), bark, Transform::IDENTITY);
    let knot = AxisBox::new(Vec3::splat(-0.15), Vec3::splat(0.15)).unwrap();
    let knotted = placed(Vec3::new(0.0, 0.7, 0.0), Vec3::Z, 45.0, Vec3::ONE);
    tree.add_primitive(Shape::AxisBox(knot), bark, knotted);
    for k in 0..4 {
        let angle = 90.0 * f64::from(k) + 10.0;
        let at = placed(Vec3::new(0.0, 1.5, 0.0), Vec3::Y, angle, Vec3::ONE)
            .then_after(&Transform::translate(Vec3::new(0.3, 0.0, 0.0)).unwrap());
        let material = (k == 2).then_some(gold);
        tree.add_instance(leaf, material, at);
    }
    let tree = world.add_definition(tree);

    let mut rock = Objects::default();
    let mesh = rock.add_mesh(soup(&mut rng, 60));
    rock.add_mesh_instance(mesh, bark, Transform::IDENTITY);
    let rock = world.add_definition(rock);

    let mut ground = Objects::default();
    let plane = Plane::new(Vec3::ZERO, Vec3::Y).unwrap();
    ground.add_primitive(Shape::Plane(plane), bark, Transform::IDENTITY);
    let ground = world.add_definition(ground);

    let mut grove = Objects::default();
    for k in 0..3 {
        let at = Vec3::new(1.2 * f64::from(k) - 1.2, 0.0, 0.3 * f64::from(k));
        let t = placed(at, Vec3::new(0.1, 1.0, 0.0), 25.0 * f64::from(k), Vec3::ONE);
        grove.add_instance(tree, None, t);
    }
    let grove = world.add_definition(grove);

    for k in 0..4 {
        let at = Vec3::new(4.0 * f64::from(k % 2) - 2.0, 0.0, 4.0 * f64::from(k / 2));
        let scale = Vec3::new(1.0, 0.8 + 0.2 * f64::from(k), 1.1);
        let material = (k == 3).then_some(MaterialId(3));
        world.add_instance(
            grove,
            material,
            placed(at, Vec3::Y, 33.0 * f64::from(k), scale),
        );
    }
    for k in 0..3 {
        let at = Vec3::new(1.5 * f64::from(k) - 1.5, 0.4, -1.5);
        let t = placed(at, rng.unit_vector(), 70.0 * f64::from(k), Vec3::splat(0.7));
        world.add_instance(rock, None, t);
    }
    let down = Transform::translate(Vec3::new(0.0, -0.01, 0.0)).unwrap();
    world.add_instance(ground, None, down);
    let sun = Sphere::new(Vec3::new(0.0, 4.0, 8.0), 0.8).unwrap();
    world.add_primitive(Shape::Sphere(sun), gold, Transform::IDENTITY);
    world
}

/// Whether `a` and `b` agree within 1e-6 relative.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1.0)
}

/// Camera rays through a 64×48 image, then random rays and segments.
fn rays() -> Vec<Ray> {
    let camera = Camera::new(
        Vec3::new(0.0, 3.0, -6.0),
        Vec3::new(0.0, 0.8, 2.0),
        Vec3::Y,
        50.0,
    )
    .unwrap();
    let mut rays: Vec<Ray> = (0..48)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .map(|(x, y)| camera.ray(64, 48, f64::from(x) + 0.5, f64::from(y) + 0.5))
        .collect();
    let mut rng = Rng::new(7);
    for i in 0..3000 {
        let origin = rng.point_in(Vec3::new(-4.0, -0.5, -2.0), Vec3::new(4.0, 3.0, 6.0));
        let dir = rng.unit_vector();
        rays.push(if i % 2 == 0 {
            Ray::new(origin, dir)
        } else {
            Ray::segment(origin, dir, rng.range(0.2, 4.0))
        });
    }
    rays
}

#[test]
fn instances_hit_what_their_flattened_copies_hit_through_every_structure() {
    let world = forest();
    world.check_instances().unwrap();
    let (flat, numbers) = flattened(&world);
    assert_eq!(world.primitive_count(), flat.primitive_count());
    assert_eq!(numbers.len(), flat.primitive_count());
    let oracle = World::build(&flat, AccelKind::Linear);
    let rays = rays();
    let expected: Vec<_> = rays.iter().map(|ray| oracle.intersect(ray)).collect();
    let hits = expected.iter().flatten().count();
    assert!(hits > rays.len() / 2, "{hits} hits");
    let mut pairs: Vec<(AccelKind, AccelKind)> = AccelKind::ALL.iter().map(|&k| (k, k)).collect();
    pairs.extend([
        (AccelKind::Bvh, AccelKind::KdTree),
        (AccelKind::Grid, AccelKind::Bvh),
        (AccelKind::KdTree, AccelKind::Grid),
    ]);
    for (top, bottom) in pairs {
        let instanced = World::build_levels(&world, top, bottom);
        assert_eq!(instanced.instance_count(), 8, "{top:?}/{bottom:?}");
        for (ray, want) in rays.iter().zip(&expected) {
            let got = instanced.intersect(ray);
            let at = format!("{top:?}/{bottom:?} {ray:?}");
            assert_eq!(got.is_some(), want.is_some(), "{at}");
            assert_eq!(instanced.occluded(ray), want.is_some(), "{at}");
            let (Some(got), Some(want)) = (got, want) else {
                continue;
            };
            assert_eq!(numbers[got.primitive.0 as usize], want.primitive.0, "{at}");
            assert!(close(got.t(), want.t()), "{at}: t {} {}", got.t(), want.t());
            let (a, b) = (instanced.surface(ray, &got), oracle.surface(ray, want));
            assert!((a.normal - b.normal).length() <= 1e-6, "{at}");
            assert!((a.point - b.point).length() <= 1e-6 * b.point.length().max(1.0));
            assert_eq!(a.material, b.material, "{at}");
        }
    }
}

#[test]
fn the_placement_names_the_top_level_instance_and_the_primitive_in_it() {
    let world = forest();
    let instanced = World::new(&world);
    // The sun is the world's own shape 0; the first grove (instance 0)
    // numbers its primitives from 1 on.
    let sun = Ray::new(Vec3::new(0.0, 4.0, 0.0), Vec3::Z);
    let hit = instanced.intersect(&sun).unwrap();
    assert_eq!(hit.primitive.0, 0);
    assert_eq!(instanced.placement(hit.primitive), None);
    let trunk = Ray::new(Vec3::new(-2.0 - 1.2, 0.5, -3.0), Vec3::Z);
    let hit = instanced.intersect(&trunk).unwrap();
    let in_grove = hit.primitive.0 - 1;
    // A grove: 3 trees of a trunk, a knot and 4 leaves of 2 shapes and 40
    // triangles.
    assert!(in_grove < 3 * (2 + 4 * 42));
    assert_eq!(instanced.placement(hit.primitive), Some((0, in_grove)));
}
