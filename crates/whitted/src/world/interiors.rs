//! What a ray starting inside a glass sphere can meet first. Of a glass
//! sphere's ray tree about half the rays start inside it (refracted into
//! it, or reflected inside it); such a ray leaves through the sphere
//! unless something else reaches into the ball, so its closest hit is
//! found among the sphere and the few entries that do, with no walk
//! (mount: four glass spheres over a terrain, touching each other).
//!
//! The hit is the one the walk would find, bit for bit. The ray's segment
//! from its origin to the sphere's hit lies in the ball (both ends do, to
//! within rounding, and the ball is convex). Every other entry's hits lie
//! on its triangle, in its box, or on its plane; those that do not come
//! within [`INTERIOR_MARGIN`] of the ball, far more than any rounding,
//! cannot be hit before the sphere. The rest are listed and tested as the
//! walk's leaves test them, with its ties left to it
//! ([`World::intersect_passed`]'s rules); and when the sphere's own test
//! finds nothing (a ray grazing it from inside, where rounding decides),
//! the walk decides too. The exception is the one the shadow steps have: a
//! structure that culls each primitive by its box (the grid, the kd-tree's
//! loose list) could turn away a hit rounded an ulp outside it, which the
//! list keeps.

use rayon::prelude::*;

use super::entry::{Entry, EntryKind};
use super::shadow_path::{PassedEntries, near_tie};
use super::{Hit, MaterialId, Primitive, PrimitiveId, World};
use crate::math::{Aabb, Ray, Vec3};
use crate::shape::{Shape, Sphere};

/// How far an entry must stay from a sphere's ball not to be listed,
/// relative to the size of the coordinates of the sphere or of the entry,
/// whichever is larger: far above the rounding of any hit point (a few
/// times 1e-16 of its coordinates).
const INTERIOR_MARGIN: f64 = 1e-9;

/// Entries measured against the spheres per parallel task.
const ENTRIES_PER_TASK: usize = 4096;

/// For the glass spheres of a world, what reaches into each
/// ([`World::interiors`]).
#[derive(Clone, Debug, Default)]
pub struct Interiors {
    /// Per primitive number up to the last such sphere's, its position in
    /// `spheres`, or `u32::MAX`.
    index: Vec<u32>,
    spheres: Vec<Interior>,
}

/// One sphere and the other entries reaching into its ball, which a ray
/// from inside it tests after it.
#[derive(Clone, Debug)]
struct Interior {
    sphere: Sphere,
    others: PassedEntries,
    /// Whether `others` holds a triangle.
    triangles: bool,
}

impl Interiors {
    /// How many spheres a ray from inside needs no walk for.
    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    /// True when there is none.
    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    #[inline]
    fn get(&self, primitive: PrimitiveId) -> Option<&Interior> {
        let &k = self.index.get(primitive.0 as usize)?;
        self.spheres.get(k as usize)
    }
}

/// A candidate sphere: its number, centre, radius and the distance from
/// its ball within which an entry is listed.
#[derive(Clone, Copy, Debug)]
struct Ball {
    number: u32,
    center: Vec3,
    radius: f64,
    margin: f64,
}

impl Ball {
    /// How near the ball an entry of coordinates up to `scale` in size
    /// must come to be listed: the radius and the larger of the two sizes'
    /// margins (a hit's rounding grows with its own coordinates).
    fn reach(&self, scale: f64) -> f64 {
        self.radius + self.margin.max(INTERIOR_MARGIN * scale)
    }

    /// True when `bounds` comes within the margin of the ball.
    fn reaches_box(&self, bounds: &Aabb) -> bool {
        let below = (bounds.min - self.center).max(Vec3::ZERO);
        let above = (self.center - bounds.max).max(Vec3::ZERO);
        let reach = self.reach(scale_of(bounds));
        (below + above).length_squared() <= reach * reach
    }

    /// True when the triangle of `corners`, within `bounds`, comes within
    /// the margin of the ball (a degenerate one whose distance is not a
    /// number does).
    fn reaches_triangle(&self, corners: &[Vec3; 3], bounds: &Aabb) -> bool {
        let reach = self.reach(scale_of(bounds));
        let distance = triangle_distance_squared(self.center, corners);
        distance.is_nan() || distance <= reach * reach
    }

    /// True when `sphere` comes within the margin of the ball.
    fn reaches_sphere(&self, sphere: &Sphere) -> bool {
        let scale = sphere.center().abs().max_element() + sphere.radius();
        let reach = self.reach(scale) + sphere.radius();
        (sphere.center() - self.center).length_squared() <= reach * reach
    }

    /// The lowest x of the ball, margin included: the key the balls are
    /// sorted by.
    fn low_x(&self) -> f64 {
        self.center.x - self.radius - self.margin
    }
}

/// The size of the coordinates in `bounds`: the largest in magnitude.
fn scale_of(bounds: &Aabb) -> f64 {
    bounds.min.abs().max(bounds.max.abs()).max_element()
}

impl<'a> World<'a> {
    /// For each untransformed sphere of this level (not one in an
    /// instance) whose material `candidate` accepts, the entries that come
    /// within [`INTERIOR_MARGIN`] of its ball: a triangle by its distance,
    /// a sphere by its ball, any other bounded entry by its box, an
    /// untransformed plane by its distance and any other unbounded entry
    /// always. A sphere is left out when one of those is found by a search
    /// or is an instance, or when it and they are more than a
    /// [`PassedEntries`] holds.
    ///
    /// The spheres are sorted by their lowest x and each entry is measured
    /// only against those whose x range can meet its box: one box per
    /// entry when the spheres are few and small, nothing at all without
    /// candidates.
    pub fn interiors(&self, candidate: impl Fn(MaterialId) -> bool) -> Interiors {
        let mut balls: Vec<Ball> = self
            .shapes
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match p {
                Primitive {
                    shape: Shape::Sphere(s),
                    transform: None,
                    material,
                } if candidate(*material) => Some(Ball {
                    number: i as u32,
                    center: s.center(),
                    radius: s.radius(),
                    margin: INTERIOR_MARGIN * (s.center().abs().max_element() + s.radius()),
                }),
                _ => None,
            })
            .collect();
        if balls.is_empty() {
            return Interiors::default();
        }
        balls.sort_by(|a, b| a.low_x().total_cmp(&b.low_x()));
        let widest = balls
            .iter()
            .map(|b| 2.0 * (b.radius + b.margin))
            .fold(0.0, f64::max);
        // (ball, entry position) for every entry reaching into a ball.
        let mut reaching: Vec<(u32, u32)> = self
            .entries
            .par_chunks(ENTRIES_PER_TASK)
            .enumerate()
            .flat_map_iter(|(chunk, entries)| {
                let first = (chunk * ENTRIES_PER_TASK) as u32;
                entries.iter().zip(first..).flat_map(|(e, position)| {
                    self.balls_reached(e, &balls, widest)
                        .map(move |k| (k as u32, position))
                })
            })
            .collect();
        reaching.sort_unstable();
        let mut interiors = Interiors::default();
        for (k, ball) in balls.iter().enumerate() {
            let from = reaching.partition_point(|&(b, _)| b < k as u32);
            let to = reaching.partition_point(|&(b, _)| b <= k as u32);
            let positions: Vec<u32> = reaching[from..to].iter().map(|&(_, p)| p).collect();
            if let Some(interior) = self.interior(ball, &positions) {
                let number = ball.number as usize;
                if interiors.index.len() <= number {
                    interiors.index.resize(number + 1, u32::MAX);
                }
                interiors.index[number] = interiors.spheres.len() as u32;
                interiors.spheres.push(interior);
            }
        }
        interiors
    }

    /// The closest hit of `ray`, which leaves primitive `primitive`: when
    /// that is a sphere of `interiors` and the ray starts inside its ball,
    /// the closest among the entries listed for it; the walk
    /// ([`World::intersect`]) otherwise, or when two of those are hit
    /// within a billionth of each other, or when the sphere's own test
    /// finds nothing.
    #[inline]
    pub fn intersect_from(
        &self,
        ray: &Ray,
        primitive: PrimitiveId,
        interiors: &Interiors,
    ) -> Option<Hit> {
        if let Some(inside) = interiors.get(primitive)
            && let Some(hit) = self.closest_inside(ray, primitive, inside)
        {
            return Some(hit);
        }
        self.intersect(ray)
    }

    /// [`World::intersect_from`] for a ray leaving sphere `primitive`,
    /// `None` where the walk must decide.
    fn closest_inside(&self, ray: &Ray, primitive: PrimitiveId, inside: &Interior) -> Option<Hit> {
        let (center, radius) = (inside.sphere.center(), inside.sphere.radius());
        if (ray.origin - center).length_squared() > radius * radius {
            return None;
        }
        let own = Hit {
            primitive,
            shape_hit: inside.sphere.intersect(ray)?,
        };
        if inside.others.is_empty() {
            return Some(own);
        }
        // The others, up to just past the sphere's hit to see a near tie.
        let (lower, upper) = near_tie(own.t());
        let mut clipped = *ray;
        clipped.t_max = upper;
        match self.closest_listed(&clipped, &inside.others, inside.triangles) {
            Ok(None) => Some(own),
            Ok(Some(other)) if other.t() < lower => Some(other),
            _ => None,
        }
    }

    /// The balls (positions in `balls`, sorted by their lowest x, none
    /// wider than `widest`) that entry `e` comes near.
    fn balls_reached<'b>(
        &self,
        e: &'b Entry,
        balls: &'b [Ball],
        widest: f64,
    ) -> impl Iterator<Item = usize> + 'b {
        let bounds = self.entry_bounds(e);
        // A ball can meet the box only if its x range does, widened by the
        // entry's own margin where that is the larger.
        let margin = INTERIOR_MARGIN * scale_of(&bounds);
        let first = balls.partition_point(|b| b.low_x() < bounds.min.x - widest - margin);
        let last = balls.partition_point(|b| b.low_x() <= bounds.max.x + margin);
        let sphere = (e.kind == EntryKind::Sphere).then(|| e.as_sphere());
        (first..last).filter(move |&k| {
            let ball = &balls[k];
            match (sphere, e.corners()) {
                (Some(s), _) => ball.reaches_sphere(&s),
                (None, Some(corners)) => {
                    ball.reaches_box(&bounds) && ball.reaches_triangle(corners, &bounds)
                }
                (None, None) => ball.reaches_box(&bounds),
            }
        })
    }

    /// The interior of `ball`, reached by the entries at `positions` (its
    /// own entry among them); `None` when one of the others, or of the
    /// unbounded entries reaching it, cannot be listed, or when they are
    /// too many.
    fn interior(&self, ball: &Ball, positions: &[u32]) -> Option<Interior> {
        let own = |&p: &u32| {
            let e = &self.entries[p as usize];
            e.kind == EntryKind::Sphere && e.number == ball.number
        };
        let mut others = PassedEntries::EMPTY;
        for &position in positions.iter().filter(|p| !own(p)) {
            if !self.closed_form(&self.entries[position as usize]) {
                return None;
            }
            others.push(position, &self.entries);
        }
        for (i, e) in self.unbounded.iter().enumerate() {
            if self.plane_misses(e, ball) {
                continue;
            }
            if !self.closed_form(e) {
                return None;
            }
            others.push_unbounded(i);
        }
        let triangles = others
            .entries()
            .any(|p| self.entries[p as usize].kind == EntryKind::Triangle);
        (positions.iter().any(own) && others.is_listed()).then_some(Interior {
            sphere: Sphere::from_accepted(ball.center, ball.radius),
            others,
            triangles,
        })
    }

    /// True when unbounded entry `e` is a plane without a transform that
    /// stays beyond the margin of `ball`.
    fn plane_misses(&self, e: &Entry, ball: &Ball) -> bool {
        if e.kind != EntryKind::Primitive {
            return false;
        }
        let Primitive {
            shape: Shape::Plane(plane),
            transform: None,
            ..
        } = &self.shapes[e.number as usize]
        else {
            return false;
        };
        let scale = plane.point().abs().max_element();
        (ball.center - plane.point()).dot(plane.normal()).abs() > ball.reach(scale)
    }
}

/// The squared distance from `p` to the triangle of `corners` (its closest
/// point found by the triangle's Voronoi regions: Ericson, *Real-Time
/// Collision Detection*, 5.1.5). A degenerate triangle (no area) gives the
/// distance to its segment or point.
fn triangle_distance_squared(p: Vec3, [a, b, c]: &[Vec3; 3]) -> f64 {
    let (ab, ac, ap) = (*b - *a, *c - *a, p - *a);
    if ab.cross(ac).length_squared() == 0.0 {
        // Degenerate (the regions below divide by an edge's length and by
        // the area): the nearest of its three edges.
        return [(*a, *b), (*b, *c), (*c, *a)]
            .iter()
            .map(|&(s, t)| segment_distance_squared(p, s, t))
            .fold(f64::INFINITY, f64::min);
    }
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length_squared();
    }
    let bp = p - *b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length_squared();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (ap - v * ab).length_squared();
    }
    let cp = p - *c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length_squared();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (ap - w * ac).length_squared();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (bp - w * (*c - *b)).length_squared();
    }
    let denom = va + vb + vc;
    let (v, w) = (vb / denom, vc / denom);
    (ap - v * ab - w * ac).length_squared()
}

/// The squared distance from `p` to the segment from `s` to `t`.
fn segment_distance_squared(p: Vec3, s: Vec3, t: Vec3) -> f64 {
    let st = t - s;
    let length = st.length_squared();
    let along = if length > 0.0 {
        ((p - s).dot(st) / length).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - s - along * st).length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::math::random::Rng;
    use crate::math::{Transform, offset_ray_origin};
    use crate::mesh::TriangleMesh;
    use crate::shape::{Cylinder, Plane, Torus};
    use crate::world::{Objects, scattered_triangles, turned_square};
    use std::f64::consts::SQRT_2;

    const GLASS: MaterialId = MaterialId(1);

    fn glass(m: MaterialId) -> bool {
        m == GLASS
    }

    fn sphere(objects: &mut Objects, centre: Vec3, radius: f64, material: MaterialId) {
        let s = Sphere::new(centre, radius).unwrap();
        objects.add_primitive(Shape::Sphere(s), material, Transform::IDENTITY);
    }

    /// The numbers of the primitives listed for sphere `number`, and
    /// whether a plane is; `None` when it has no interior.
    fn listed(world: &World, interiors: &Interiors, number: u32) -> Option<(Vec<u32>, u32)> {
        let inside = interiors.get(PrimitiveId(number))?;
        let mut numbers: Vec<u32> = inside
            .others
            .entries()
            .map(|p| world.entries[p as usize].number)
            .collect();
        numbers.sort_unstable();
        Some((numbers, inside.others.unbounded_bits()))
    }

    #[test]
    fn the_triangle_distance_is_the_nearest_of_its_points() {
        let mut rng = Rng::new(5);
        let n = 60;
        for case in 0..300 {
            let a = rng.unit_vector();
            let (b, c) = match case % 10 {
                // A segment, a segment with two corners the same, a point.
                0 => {
                    let b = a + rng.unit_vector();
                    (b, a + 0.5 * (b - a))
                }
                1 => (a, a + rng.unit_vector()),
                2 => (a, a),
                _ => (a + rng.unit_vector(), a + rng.unit_vector()),
            };
            let p = 2.0 * rng.unit_vector() * rng.uniform();
            let exact = triangle_distance_squared(p, &[a, b, c]).sqrt();
            let mut sampled = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    let q = a + u * (b - a) + v * (c - a);
                    sampled = sampled.min((p - q).length());
                }
            }
            let step = [b - a, c - a, c - b]
                .map(|e| e.length())
                .iter()
                .fold(0.0, |m: f64, &l| m.max(l))
                / n as f64;
            assert!(exact <= sampled + 1e-12, "case {case}: {exact} > {sampled}");
            assert!(
                exact >= sampled - step,
                "case {case}: {exact} < {sampled} - {step}"
            );
        }
    }

    #[test]
    fn a_sphere_lists_what_reaches_into_its_ball_and_nothing_else() {
        let mut objects = Objects::default();
        // 0: alone; 1 and 2 overlapping by a micron; 3 opaque, not a
        // candidate, touching 4; 4 cut by the plane; 5 with a triangle
        // whose box, not itself, reaches in; 6 with a triangle through it.
        sphere(&mut objects, Vec3::new(0.0, 5.0, 0.0), 1.0, GLASS);
        sphere(&mut objects, Vec3::new(4.0, 5.0, 0.0), 1.0, GLASS);
        sphere(&mut objects, Vec3::new(6.0 - 1e-6, 5.0, 0.0), 1.0, GLASS);
        sphere(&mut objects, Vec3::new(10.0, 0.5, 0.0), 1.0, MaterialId(0));
        sphere(&mut objects, Vec3::new(12.0 - 1e-6, 0.5, 0.0), 1.0, GLASS);
        sphere(&mut objects, Vec3::new(0.0, 5.0, 10.0), 1.0, GLASS);
        sphere(&mut objects, Vec3::new(5.0, 5.0, 10.0), 1.0, GLASS);
        let floor = Plane::new(Vec3::ZERO, Vec3::Y).unwrap();
        objects.add_primitive(Shape::Plane(floor), MaterialId(0), Transform::IDENTITY);
        let positions = vec![
            // On the plane x + z = 10 + 1.5√2, 1.5 from sphere 5's centre,
            // which its box holds.
            Vec3::new(-3.0, 3.0, 13.0 + 1.5 * SQRT_2),
            Vec3::new(3.0, 3.0, 7.0 + 1.5 * SQRT_2),
            Vec3::new(0.0, 8.0, 10.0 + 1.5 * SQRT_2),
            // Through sphere 6.
            Vec3::new(4.0, 5.0, 9.0),
            Vec3::new(6.0, 5.0, 9.0),
            Vec3::new(5.0, 5.0, 11.0),
        ];
        let mesh = TriangleMesh::new(positions, vec![[0, 1, 2], [3, 4, 5]]).unwrap();
        let mesh = objects.add_mesh(mesh);
        objects.add_mesh_instance(mesh, MaterialId(0), Transform::IDENTITY);
        let first_triangle = objects.primitives.len() as u32;
        for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
            let world = World::build(&objects, kind);
            let interiors = world.interiors(glass);
            assert_eq!(interiors.len(), 6, "{kind:?}");
            let list = |n| listed(&world, &interiors, n);
            assert_eq!(list(0), Some((vec![], 0)), "{kind:?}");
            assert_eq!(list(1), Some((vec![2], 0)), "{kind:?}");
            assert_eq!(list(2), Some((vec![1], 0)), "{kind:?}");
            assert_eq!(list(3), None, "{kind:?}");
            assert_eq!(list(4), Some((vec![3], 1)), "{kind:?}");
            assert_eq!(list(5), Some((vec![], 0)), "{kind:?}");
            assert_eq!(list(6), Some((vec![first_triangle + 1], 0)), "{kind:?}");
        }
    }

    #[test]
    fn a_sphere_reached_by_a_searched_shape_or_too_many_has_no_interior() {
        let mut objects = Objects::default();
        sphere(&mut objects, Vec3::ZERO, 1.0, GLASS);
        let torus = Torus::new(1.0, 0.2).unwrap();
        objects.add_primitive(Shape::Torus(torus), MaterialId(0), Transform::IDENTITY);
        sphere(&mut objects, Vec3::new(10.0, 0.0, 0.0), 1.0, GLASS);
        let mut rng = Rng::new(3);
        for _ in 0..20 {
            let centre = Vec3::new(10.0, 0.0, 0.0) + rng.unit_vector();
            sphere(&mut objects, centre, 0.1, MaterialId(0));
        }
        // A mesh moved, so kept as an instance, through a third.
        sphere(&mut objects, Vec3::new(20.0, 0.0, 0.0), 1.0, GLASS);
        let corners = vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::Z,
        ];
        let mesh = objects.add_mesh(TriangleMesh::new(corners, vec![[0, 1, 2]]).unwrap());
        let moved = Transform::translate(Vec3::new(20.0, 0.0, 0.0)).unwrap();
        objects.add_mesh_instance(mesh, MaterialId(0), moved);
        let world = World::build(&objects, AccelKind::Bvh);
        assert!(world.interiors(glass).is_empty());
        assert!(world.interiors(|_| false).is_empty());
    }

    /// Glass spheres crowded together with opaque ones, triangles, polygons
    /// and moved cylinders cutting through some, and a floor plane cutting
    /// others.
    fn crowded_scene(rng: &mut Rng) -> Objects {
        let mut objects = Objects::default();
        for i in 0..80 {
            let centre = 6.0 * rng.unit_vector() * rng.uniform();
            let material = if i % 4 == 0 { MaterialId(0) } else { GLASS };
            sphere(&mut objects, centre, 0.4 + 0.6 * rng.uniform(), material);
        }
        let mesh = objects.add_mesh(scattered_triangles(rng, 60, 6.0));
        objects.add_mesh_instance(mesh, MaterialId(0), Transform::IDENTITY);
        for _ in 0..20 {
            let centre = 6.0 * rng.unit_vector() * rng.uniform();
            let polygon = turned_square(rng, centre);
            objects.add_primitive(Shape::Polygon(polygon), MaterialId(0), Transform::IDENTITY);
            let cylinder = Cylinder::new(0.2 + 0.3 * rng.uniform(), 1.5, true).unwrap();
            let moved = Transform::translate(6.0 * rng.unit_vector() * rng.uniform()).unwrap();
            objects.add_primitive(Shape::Cylinder(cylinder), MaterialId(0), moved);
        }
        let floor = Plane::new(Vec3::new(0.0, -4.0, 0.0), Vec3::Y).unwrap();
        objects.add_primitive(Shape::Plane(floor), MaterialId(0), Transform::IDENTITY);
        objects
    }

    /// The hits of rays leaving sphere `number` of `objects` from random
    /// points of its surface, inwards and outwards, found by
    /// [`World::intersect_from`] and by the walk.
    fn from_sphere(
        world: &World,
        objects: &Objects,
        interiors: &Interiors,
        number: u32,
        rng: &mut Rng,
    ) -> Option<(Ray, Option<Hit>, Option<Hit>)> {
        let Shape::Sphere(s) = &objects.primitives[number as usize].shape else {
            unreachable!()
        };
        // A point on the sphere as a hit finds it, and a ray leaving it as
        // the integrator makes one.
        let towards = rng.unit_vector();
        let probe = Ray::new(s.center() + 3.0 * towards, -towards);
        let hit = Hit {
            primitive: PrimitiveId(number),
            shape_hit: Shape::Sphere(*s).intersect(&probe)?,
        };
        let surface = world.surface(&probe, &hit);
        let dir = rng.unit_vector();
        let origin = offset_ray_origin(surface.point, surface.point_error, surface.normal, dir);
        let ray = Ray::new(origin, dir);
        let found = world.intersect_from(&ray, PrimitiveId(number), interiors);
        Some((ray, found, world.intersect(&ray)))
    }

    /// A hit's primitive and the bits of its parameter.
    fn bits(hit: Option<Hit>) -> Option<(PrimitiveId, u64)> {
        hit.map(|h| (h.primitive, h.shape_hit.t.to_bits()))
    }

    #[test]
    fn rays_from_inside_a_sphere_find_the_walks_hits() {
        let mut rng = Rng::new(17);
        let objects = crowded_scene(&mut rng);
        for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
            let world = World::build(&objects, kind);
            let interiors = world.interiors(glass);
            assert!(interiors.len() > 40, "{kind:?}: {}", interiors.len());
            // Rays from inside whose hit is another entry listed, rays from
            // inside leaving through the sphere, rays from outside.
            let mut seen = [0; 3];
            for i in 0..6000 {
                let number = (i % 80) as u32;
                let Some((ray, found, expected)) =
                    from_sphere(&world, &objects, &interiors, number, &mut rng)
                else {
                    continue;
                };
                assert_eq!(
                    bits(found),
                    bits(expected),
                    "{kind:?} sphere {number} {ray:?}"
                );
                let Shape::Sphere(s) = &objects.primitives[number as usize].shape else {
                    unreachable!()
                };
                let inside = (ray.origin - s.center()).length() < s.radius();
                match expected {
                    _ if !inside => seen[2] += 1,
                    Some(h) if h.primitive.0 != number => seen[0] += 1,
                    _ => seen[1] += 1,
                }
            }
            assert!(seen.iter().all(|&n| n > 100), "{kind:?}: {seen:?}");
        }
    }
    #[test]
    fn two_spheres_in_one_place_leave_the_choice_to_the_walk() {
        let mut objects = Objects::default();
        let mut rng = Rng::new(23);
        for _ in 0..2 {
            sphere(&mut objects, Vec3::new(0.5, -0.25, 2.0), 1.5, GLASS);
        }
        sphere(&mut objects, Vec3::new(3.0, 0.0, 2.0), 1.0, MaterialId(0));
        for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
            let world = World::build(&objects, kind);
            let interiors = world.interiors(glass);
            assert_eq!(interiors.len(), 2, "{kind:?}");
            let mut inside = 0;
            for i in 0..400 {
                let number = i % 2;
                let Some((ray, found, expected)) =
                    from_sphere(&world, &objects, &interiors, number, &mut rng)
                else {
                    continue;
                };
                assert_eq!(
                    bits(found),
                    bits(expected),
                    "{kind:?} sphere {number} {ray:?}"
                );
                inside += usize::from(expected.is_some_and(|h| h.primitive.0 < 2));
            }
            assert!(inside > 100, "{kind:?}: {inside}");
        }
    }
}
