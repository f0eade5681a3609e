//! Rays that travel together, as one query: up to [`PACKET_SIZE`] rays
//! (a tile row's camera rays) whose closest hits are found by one walk of
//! the BVH ([`Bvh::intersect_packet_by_leaf`]), with exactly the
//! answers each ray's own walk gives.
//!
//! The packet walk tests a primitive with other intervals than the single
//! walk does; the answers stay the same only where a primitive's reported
//! parameter does not depend on its interval: triangles and closed-form
//! shapes ([`crate::shape::Shape::closed_form`]). A world with other
//! entries (shapes found by search, instances, whose own walks break ties
//! by their order) or another structure walks a packet's rays one at a
//! time, as do packets the walk cannot take together and the lanes where
//! it saw two primitives hit at the same parameter.
//!
//! A leaf of triangles alone that several lanes of a set of four reach is
//! tested across them, four lanes at once (`watertight_rays4`): each lane
//! sees the triangles in the leaf's order with its own interval, ended at
//! each hit as [`leaf_hit`] ends it, so each gets what its own loop would
//! get. Not in worlds of meshes of 200k triangles or more, whose
//! triangles, under a pixel, seldom meet several lanes: the test across
//! them was slower there (docs/performance-log.md).

use crate::shape::WideLanes;
use std::ops::Range;

use crate::accel::bvh::PACKET_LANES;
use crate::accel::kernel;
use crate::accel::{Accelerator, Backend, Bvh, QueryContext};
use crate::math::Ray;
use crate::shape::{FourLanes, LANES, RayShear, ShapeHit};

use super::entry::{EntryKind, Query, Rest, leaf_hit, nearer};
use super::{Hit, PrimitiveId, World};

/// The most rays a packet holds.
pub const PACKET_SIZE: usize = PACKET_LANES;

/// How many lanes of a set of four must reach a leaf of triangles for the
/// set to be tested across its lanes.
const ACROSS_FROM: u32 = 2;

impl<'a> World<'a> {
    /// True when [`Self::intersect_packet`] walks packets together under
    /// the default backend ([`Backend::current`]; else it walks their rays
    /// one at a time, and callers may as well).
    pub fn walks_packets(&self) -> bool {
        self.walks_packets_with(Backend::current())
    }

    /// True when [`Self::intersect_packet`] walks packets together with a
    /// query context of `backend`: the walk needs AVX.
    pub(super) fn walks_packets_with(&self, backend: Backend) -> bool {
        self.packet_walk && backend.has_avx()
    }

    /// Whether packets of rays may walk this world's structure together
    /// (on a backend with AVX): a BVH whose entries all report parameters
    /// that do not depend on the interval they are tested with (see the
    /// module documentation).
    pub(super) fn packets_allowed(&self) -> bool {
        matches!(self.accel, Accelerator::Bvh(_))
            && self.entries.iter().all(|e| match e.kind {
                EntryKind::Triangle | EntryKind::Sphere | EntryKind::Polygon | EntryKind::Axial => {
                    true
                }
                EntryKind::Primitive => self.shapes[e.number as usize].shape.closed_form(),
                EntryKind::Instance | EntryKind::Placed => false,
            })
    }

    /// The closest hit of each of `rays` (at most [`PACKET_SIZE`]) into
    /// the same place of `hits`, as [`Self::intersect_with`] finds it for
    /// each, found by one walk where the world and the rays allow it (see
    /// the module documentation).
    ///
    /// # Panics
    ///
    /// When there are more than [`PACKET_SIZE`] rays or fewer hits than
    /// rays.
    pub fn intersect_packet(&self, rays: &[Ray], ctx: &mut QueryContext, hits: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET_SIZE, "{} rays in a packet", rays.len());
        let hits = &mut hits[..rays.len()];
        let all = (1u32 << rays.len()) - 1;
        let mut alone = match &self.accel {
            Accelerator::Bvh(bvh) if self.walks_packets_with(ctx.backend) && !rays.is_empty() => {
                self.closest_packet(bvh, rays, ctx, hits)
            }
            _ => all,
        };
        while alone != 0 {
            let lane = alone.trailing_zeros() as usize;
            alone &= alone - 1;
            hits[lane] = self.intersect_with(&rays[lane], ctx);
        }
    }

    /// The packet walk of [`Self::intersect_packet`] over `bvh`, this
    /// world's structure: each lane's closest hit in `hits`; returns the
    /// lanes to walk again alone (all of them when the packet cannot be
    /// walked together).
    fn closest_packet(
        &self,
        bvh: &Bvh,
        rays: &[Ray],
        ctx: &mut QueryContext,
        hits: &mut [Option<Hit>],
    ) -> u32 {
        let all = (1u32 << rays.len()) - 1;
        let definitions = &self.definitions;
        // A lane's query (its triangle shear) is made when the lane first
        // reaches an entry (most of a packet's lanes that miss never do),
        // or when a leaf is first tested across the lanes.
        let mut queries: [Option<Query>; PACKET_SIZE] = [None; PACKET_SIZE];
        let mut inner = QueryContext::new(ctx.coherence);
        hits.fill(None);
        let mut clipped = [rays[0]; PACKET_SIZE];
        let rays = if self.unbounded.is_empty() {
            rays
        } else {
            for (lane, ray) in rays.iter().enumerate() {
                clipped[lane] = *ray;
                let query = queries[lane].insert(Query::new(ray, self.has_triangles));
                for e in &self.unbounded {
                    if let Some((primitive, h)) = self.intersect_other(
                        definitions,
                        e,
                        (query, clipped[lane].t_max, Rest::Test),
                        &mut inner,
                    ) {
                        clipped[lane].t_max = h.t;
                        hits[lane] = Some(Hit {
                            primitive: PrimitiveId(primitive),
                            shape_hit: h,
                        });
                    }
                }
            }
            &clipped[..rays.len()]
        };
        // Leaves of triangles alone are tested across the lanes when each
        // of the two sets of four lanes is sheared alike (`None` until a
        // leaf needs them, `Some(None)` when a set is not).
        let mut across: Option<Option<[<WideLanes as FourLanes>::Rays; 2]>> = None;
        let backend = ctx.backend;
        let tied = bvh.intersect_packet_by_leaf(
            rays,
            backend,
            &mut ctx.counters,
            |lanes, range, t_max| {
                let mut found = 0;
                // The lanes left to test one by one.
                let mut alone = lanes;
                if WideLanes::ANY
                    && !self.big_meshes
                    && crowded_halves(lanes) != 0
                    && self.all_triangles(range.clone())
                {
                    let across = across.get_or_insert_with(|| {
                        for (lane, ray) in rays.iter().enumerate() {
                            queries[lane]
                                .get_or_insert_with(|| Query::new(ray, self.has_triangles));
                        }
                        // SAFETY: packets are walked together only in the
                        // kernels whose lanes are `WideLanes`, with their
                        // features.
                        unsafe {
                            kernel::with_packet_features(
                                #[inline(always)]
                                || ray_lanes::<WideLanes>(rays, &queries),
                            )
                        }
                    });
                    if let Some(across) = across {
                        let together = lanes & crowded_halves(lanes);
                        let range = range.clone();
                        // SAFETY: as above, for both.
                        found = unsafe {
                            kernel::with_packet_features(
                                #[inline(always)]
                                || {
                                    self.triangles_across::<WideLanes>(
                                        range, together, t_max, across, hits,
                                    )
                                },
                            )
                        };
                        alone &= !together;
                    }
                }
                let mut bits = alone;
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let query = queries[lane]
                        .get_or_insert_with(|| Query::new(&rays[lane], self.has_triangles));
                    let number = hits[lane].map_or(u32::MAX, |h| h.primitive.0);
                    let closest = leaf_hit::<WideLanes>(
                        &self.entries,
                        range.clone(),
                        query,
                        (t_max[lane], number),
                        |e, t_max, rest| {
                            self.intersect_other(definitions, e, (query, t_max, rest), &mut inner)
                        },
                        |primitive, shape_hit| {
                            hits[lane] = Some(Hit {
                                primitive: PrimitiveId(primitive),
                                shape_hit,
                            })
                        },
                    );
                    if let Some(t) = closest {
                        t_max[lane] = t;
                        found |= 1 << lane;
                    }
                }
                found
            },
        );
        ctx.counters += inner.counters;
        tied.unwrap_or(all)
    }

    /// Whether the entries `range` are all triangles.
    #[inline]
    fn all_triangles(&self, range: Range<u32>) -> bool {
        self.entries[range.start as usize..range.end as usize]
            .iter()
            .all(|e| e.kind == EntryKind::Triangle)
    }

    /// The leaf `range` of triangles tested for the `lanes` of a packet
    /// whose rays are `across`, each lane's closest hit so far at
    /// `t_max[lane]` (on the primitive `hits[lane]` names, if any): per
    /// lane, the triangles in order, each hit before the last
    /// ([`nearer`]) written to `hits` and ending the interval, as
    /// [`leaf_hit`] does for one ray. Returns the lanes that hit, with
    /// their closest `t` left in `t_max`.
    ///
    /// # Safety
    ///
    /// Call it only in a kernel whose lanes are `L` (see [`FourLanes`]).
    #[inline(always)]
    unsafe fn triangles_across<L: FourLanes>(
        &self,
        range: Range<u32>,
        lanes: u32,
        t_max: &mut [f64; PACKET_SIZE],
        across: &[L::Rays; 2],
        hits: &mut [Option<Hit>],
    ) -> u32 {
        let mut found = 0;
        for e in &self.entries[range.start as usize..range.end as usize] {
            for (half, rays) in across.iter().enumerate() {
                let first = half * LANES;
                let mut mask = (lanes >> first) & 0b1111;
                if mask == 0 {
                    continue;
                }
                // One ulp past each lane's closest hit, to see ties.
                let ends = [0, 1, 2, 3].map(|i| t_max[first + i].next_up());
                // SAFETY: the caller's contract.
                let h = unsafe { L::triangle_across(&e.corners, rays, ends) };
                mask &= h.mask;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let lane = first + i;
                    let number = hits[lane].map_or(u32::MAX, |h| h.primitive.0);
                    if !nearer((h.t[i], e.number), (t_max[lane], number)) {
                        continue;
                    }
                    found |= 1 << lane;
                    t_max[lane] = h.t[i];
                    hits[lane] = Some(Hit {
                        primitive: PrimitiveId(e.number),
                        shape_hit: ShapeHit {
                            t: h.t[i],
                            u: h.u[i],
                            v: h.v[i],
                            part: 0,
                        },
                    });
                }
            }
        }
        found
    }
}

/// The lanes of the sets of four (lanes 0 to 3, 4 to 7) of which at least
/// [`ACROSS_FROM`] are in `lanes`: the sets worth testing across (one
/// lane alone is tested faster by itself, with its early outs).
#[inline]
fn crowded_halves(lanes: u32) -> u32 {
    let crowded = |first: usize| {
        let half = 0b1111 << first;
        if (lanes & half).count_ones() >= ACROSS_FROM {
            half
        } else {
            0
        }
    };
    crowded(0) | crowded(LANES)
}

/// The packet's rays in two sets of four lanes (the last ray repeated past
/// the packet's end), with their queries' shears; `None` when the shears
/// of one of the sets do not all make the same axis z.
///
/// # Safety
///
/// Call it only in a kernel whose lanes are `L` (see [`FourLanes`]).
#[inline(always)]
unsafe fn ray_lanes<L: FourLanes>(
    rays: &[Ray],
    queries: &[Option<Query>; PACKET_SIZE],
) -> Option<[L::Rays; 2]> {
    let last = rays.len() - 1;
    let shears: [RayShear; PACKET_SIZE] = std::array::from_fn(|lane| {
        queries[lane.min(last)].map_or_else(|| RayShear::new(&rays[lane.min(last)]), |q| q.shear())
    });
    let half = |first: usize| {
        let lane = |i: usize| (first + i).min(last);
        // SAFETY: the caller's contract.
        unsafe {
            L::rays(
                [0, 1, 2, 3].map(|i| &rays[lane(i)]),
                [0, 1, 2, 3].map(|i| &shears[first + i]),
            )
        }
    };
    Some([half(0)?, half(LANES)?])
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::accel::{AccelKind, Isa};
    use crate::math::random::Rng;
    use crate::math::{Transform, Vec3};
    use crate::mesh::TriangleMesh;
    use crate::shape::OneByOne;
    use crate::shape::{Cylinder, Plane, Polygon, Shape, Sphere, Torus};
    use crate::world::{MaterialId, Objects};

    /// Whether the current backend has AVX, which the packet walk needs
    /// (`WHITTED_ISA=sse2` turns it off).
    pub(in crate::world) fn has_avx() -> bool {
        crate::accel::Backend::current().has_avx()
    }

    /// Spheres, a triangle soup placed once, polygons, capped cylinders
    /// (some moved) and, if `floor`, an infinite plane.
    pub(in crate::world) fn closed_form_scene(rng: &mut Rng, floor: bool) -> Objects {
        let mut objects = Objects::default();
        let m = MaterialId(0);
        for _ in 0..80 {
            let centre = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
            let sphere = Sphere::new(centre, rng.range(0.05, 0.5)).unwrap();
            objects.add_primitive(Shape::Sphere(sphere), m, Transform::IDENTITY);
        }
        for _ in 0..20 {
            let c = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
            let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, y)| c + Vec3::new(0.4 * x, 0.3 * y, 0.1 * x));
            let polygon = Polygon::new(square.to_vec()).unwrap();
            objects.add_primitive(Shape::Polygon(polygon), m, Transform::IDENTITY);
            let cylinder = Cylinder::new(rng.range(0.05, 0.3), rng.range(0.2, 1.0), true).unwrap();
            let moved = Transform::translate(c).unwrap();
            objects.add_primitive(Shape::Cylinder(cylinder), m, moved);
        }
        let positions: Vec<Vec3> = (0..600)
            .map(|_| rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0)))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..200).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let soup = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
        objects.add_mesh_instance(soup, m, Transform::IDENTITY);
        if floor {
            let plane = Plane::new(Vec3::new(0.0, -2.5, 0.0), Vec3::Y).unwrap();
            objects.add_primitive(Shape::Plane(plane), m, Transform::IDENTITY);
        }
        objects
    }

    /// Packets of up to eight rays from one point, spread by up to
    /// `spread` around a direction towards the scene, as camera rays are.
    fn camera_packets(rng: &mut Rng, count: usize, spread: f64) -> Vec<Vec<Ray>> {
        (0..count)
            .map(|_| {
                let origin = rng.point_in(Vec3::splat(-9.0), Vec3::splat(9.0));
                let towards = rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0)) - origin;
                let lanes = 1 + rng.below(PACKET_SIZE as u32) as usize;
                (0..lanes)
                    .map(|_| {
                        let wobble = rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                        Ray::new(origin, (towards.normalize() + wobble).normalize())
                    })
                    .collect()
            })
            .collect()
    }

    /// Every lane of each packet gets the single walk's hit and brute
    /// force's; returns how many packets the walk took together and how
    /// many lanes hit.
    fn assert_packets_agree(objects: &Objects, packets: &[Vec<Ray>]) -> (usize, usize) {
        let world = World::new(objects);
        let brute = World::build(objects, AccelKind::Linear);
        let (mut together, mut hits) = (0, 0);
        for rays in packets {
            let mut ctx = QueryContext::default();
            let mut found = [None; PACKET_SIZE];
            world.intersect_packet(rays, &mut ctx, &mut found);
            // Every backend gives the same hits (those without AVX walk the
            // rays one by one).
            for backend in Isa::ALL.into_iter().filter_map(Backend::new) {
                let mut narrowed = QueryContext {
                    backend,
                    ..QueryContext::default()
                };
                let mut again = [None; PACKET_SIZE];
                world.intersect_packet(rays, &mut narrowed, &mut again);
                assert_eq!(again, found, "{backend:?}");
            }
            if let Accelerator::Bvh(bvh) = &world.accel
                && !rays.is_empty()
            {
                let mut scratch = [None; PACKET_SIZE];
                let all = (1 << rays.len()) - 1;
                together +=
                    usize::from(world.closest_packet(bvh, rays, &mut ctx, &mut scratch) != all);
            }
            for (lane, ray) in rays.iter().enumerate() {
                let single = world.intersect(ray);
                assert_eq!(found[lane], single, "lane {lane} of {rays:?}");
                let reference = brute.intersect(ray);
                assert_eq!(
                    single.map(|h| h.shape_hit.t),
                    reference.map(|h| h.shape_hit.t)
                );
                hits += usize::from(single.is_some());
            }
            assert!(found[rays.len()..].iter().all(Option::is_none));
        }
        (together, hits)
    }

    #[test]
    fn camera_packets_get_the_single_walks_hits() {
        let mut rng = Rng::new(5);
        for floor in [false, true] {
            let objects = closed_form_scene(&mut rng, floor);
            assert_eq!(World::new(&objects).walks_packets(), has_avx());
            let mut packets = camera_packets(&mut rng, 400, 0.002);
            packets.extend(camera_packets(&mut rng, 200, 0.05));
            let (together, hits) = assert_packets_agree(&objects, &packets);
            if has_avx() {
                assert!(together > 500, "{together}");
            }
            assert!(hits > 1000, "{hits}");
        }
    }

    #[test]
    fn scattered_rays_fall_back_to_single_walks_with_the_same_hits() {
        let mut rng = Rng::new(6);
        let objects = closed_form_scene(&mut rng, true);
        let packets: Vec<Vec<Ray>> = (0..200)
            .map(|round| {
                (0..round % (PACKET_SIZE + 1))
                    .map(|_| {
                        let origin = rng.point_in(Vec3::splat(-5.0), Vec3::splat(5.0));
                        Ray::segment(origin, rng.unit_vector(), rng.range(1.0, 8.0))
                    })
                    .collect()
            })
            .collect();
        assert_packets_agree(&objects, &packets);
    }

    #[test]
    fn hits_tied_between_leaves_are_the_single_walks_choice() {
        // Overlapping triangles and squares in the plane z = 0 (each with
        // its own box, so they lie in many leaves), and, in the second
        // world, the infinite plane z = 0 too: rays nearly straight down
        // hit several at exactly the same parameter where they overlap,
        // and the single walk keeps the first it visits (the plane, tested
        // first, where there is one). The packet hands such lanes back.
        let mut rng = Rng::new(7);
        let mut objects = Objects::default();
        let mut positions = Vec::new();
        for _ in 0..300 {
            let c = rng.point_in(Vec3::new(-6.0, -6.0, 0.0), Vec3::new(6.0, 6.0, 0.0));
            positions.extend([
                c + Vec3::new(-1.0, -1.0, 0.0),
                c + Vec3::new(1.0, -1.0, 0.0),
                c + Vec3::new(0.0, 1.0, 0.0),
            ]);
            let d = rng.point_in(Vec3::new(-6.0, -6.0, 0.0), Vec3::new(6.0, 6.0, 0.0));
            let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, y)| d + Vec3::new(0.5 * x, 0.5 * y, 0.0));
            let polygon = Polygon::new(square.to_vec()).unwrap();
            objects.add_primitive(Shape::Polygon(polygon), MaterialId(0), Transform::IDENTITY);
        }
        let triangles: Vec<[u32; 3]> = (0..300).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let mesh = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
        objects.add_mesh_instance(mesh, MaterialId(0), Transform::IDENTITY);
        let mut with_plane = objects.clone();
        let plane = Plane::new(Vec3::ZERO, Vec3::Z).unwrap();
        with_plane.add_primitive(Shape::Plane(plane), MaterialId(0), Transform::IDENTITY);
        for objects in [&objects, &with_plane] {
            let world = World::new(objects);
            let Accelerator::Bvh(bvh) = &world.accel else {
                panic!("the default structure is a BVH");
            };
            let (mut hits, mut given_back) = (0, 0);
            let rounds = 300;
            for _ in 0..rounds {
                let corner = rng.point_in(Vec3::new(-7.0, -7.0, 2.0), Vec3::new(7.0, 7.0, 2.0));
                let rays: Vec<Ray> = (0..PACKET_SIZE)
                    .map(|i| {
                        let origin = corner + Vec3::new(0.01 * i as f64, 0.0, 0.0);
                        Ray::new(origin, Vec3::new(1e-3, 1e-3, -1.0).normalize())
                    })
                    .collect();
                let mut found = [None; PACKET_SIZE];
                world.intersect_packet(&rays, &mut QueryContext::default(), &mut found);
                for (lane, ray) in rays.iter().enumerate() {
                    let single = world.intersect(ray);
                    assert_eq!(found[lane], single);
                    hits += usize::from(single.is_some());
                }
                let mut scratch = [None; PACKET_SIZE];
                let mut ctx = QueryContext::default();
                let alone = world.closest_packet(bvh, &rays, &mut ctx, &mut scratch);
                given_back += alone.count_ones() as usize;
            }
            assert!(hits > 1000, "{hits}");
            if has_avx() {
                // Walked together (not every lane given back), with ties
                // seen and handed back.
                let lanes = rounds * PACKET_SIZE;
                assert!(given_back > 100 && given_back < lanes - 100, "{given_back}");
            }
        }
    }

    /// A closed sphere of `rings × rings` quads split into triangles that
    /// share their corners, and scattered triangles: a world whose leaves
    /// all hold triangles alone.
    pub(in crate::world) fn triangles_only(rng: &mut Rng, rings: u32) -> Objects {
        let mut positions = Vec::new();
        for i in 0..=rings {
            let theta = std::f64::consts::PI * f64::from(i) / f64::from(rings);
            for j in 0..rings {
                let phi = std::f64::consts::TAU * f64::from(j) / f64::from(rings);
                let (s, c) = (theta.sin(), theta.cos());
                positions.push(2.0 * Vec3::new(s * phi.cos(), c, s * phi.sin()));
            }
        }
        let corner = |i: u32, j: u32| i * rings + j % rings;
        let mut triangles = Vec::new();
        for i in 0..rings {
            for j in 0..rings {
                let (a, b) = (corner(i, j), corner(i, j + 1));
                let (c, d) = (corner(i + 1, j), corner(i + 1, j + 1));
                triangles.extend([[a, c, b], [b, c, d]]);
            }
        }
        let mut objects = Objects::default();
        let sphere = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
        objects.add_mesh_instance(sphere, MaterialId(0), Transform::IDENTITY);
        let soup = objects.add_mesh(crate::world::scattered_triangles(rng, 300, 4.0));
        objects.add_mesh_instance(soup, MaterialId(0), Transform::IDENTITY);
        objects
    }

    #[test]
    fn leaves_of_triangles_tested_across_the_lanes_get_the_single_walks_hits() {
        let mut rng = Rng::new(9);
        let objects = triangles_only(&mut rng, 48);
        let world = World::new(&objects);
        assert!(world.entries.iter().all(|e| e.kind == EntryKind::Triangle));
        let mut packets = camera_packets(&mut rng, 600, 0.002);
        packets.extend(camera_packets(&mut rng, 300, 0.05));
        // Rays along the axes' diagonals, where the largest component of
        // neighbouring directions differs, so the lanes are not sheared
        // alike.
        for _ in 0..100 {
            let origin = rng.point_in(Vec3::splat(5.0), Vec3::splat(6.0));
            packets.push(
                (0..PACKET_SIZE)
                    .map(|_| Ray::new(origin, -Vec3::ONE + 1e-3 * rng.unit_vector()))
                    .collect(),
            );
        }
        let (together, hits) = assert_packets_agree(&objects, &packets);
        if has_avx() {
            assert!(together > 800, "{together}");
            let sheared_alike = |rays: &Vec<Ray>| {
                let queries =
                    std::array::from_fn(|lane| rays.get(lane).map(|ray| Query::new(ray, true)));
                // SAFETY: the processor has AVX, which `WideLanes` need.
                unsafe { ray_lanes::<WideLanes>(rays, &queries) }.is_some()
            };
            let alike = packets.iter().filter(|rays| sheared_alike(rays)).count();
            assert!(alike > 800 && alike < packets.len(), "{alike}");
        }
        assert!(hits > 2000, "{hits}");
    }

    #[test]
    fn each_lane_tested_across_gets_its_own_loops_hits_and_no_other_lane_changes() {
        if !has_avx() {
            return;
        }
        let mut rng = Rng::new(10);
        let objects = triangles_only(&mut rng, 32);
        let world = World::new(&objects);
        let Accelerator::Bvh(bvh) = &world.accel else {
            panic!("the default structure is a BVH");
        };
        let (mut leaves, mut lanes_hit) = (0, 0);
        for rays in camera_packets(&mut rng, 300, 0.01) {
            let queries = std::array::from_fn(|lane| rays.get(lane).map(|r| Query::new(r, true)));
            // SAFETY: the processor has AVX, which `WideLanes` need.
            let Some(across) = (unsafe { ray_lanes::<WideLanes>(&rays, &queries) }) else {
                continue;
            };
            let mut counters = crate::accel::TraversalCounters::default();
            // Every leaf the packet reaches, tested across a random subset
            // of its lanes with random interval ends, against each lane's
            // own loop.
            bvh.intersect_packet_by_leaf(
                &rays,
                Backend::current(),
                &mut counters,
                |lanes, range, _| {
                    let chosen = lanes & rng.below(256);
                    let ends: [f64; PACKET_SIZE] = std::array::from_fn(|_| rng.range(0.0, 20.0));
                    let mut t_max = ends;
                    let mut hits = [None; PACKET_SIZE];
                    // SAFETY: as above.
                    let found = unsafe {
                        world.triangles_across::<WideLanes>(
                            range.clone(),
                            chosen,
                            &mut t_max,
                            &across,
                            &mut hits,
                        )
                    };
                    for lane in 0..PACKET_SIZE {
                        let mut own = None;
                        let mut closest = None;
                        if chosen & 1 << lane != 0 {
                            closest = leaf_hit::<OneByOne>(
                                &world.entries,
                                range.clone(),
                                queries[lane].as_ref().unwrap(),
                                (ends[lane], u32::MAX),
                                |_, _, _| unreachable!("triangles only"),
                                |primitive, shape_hit| {
                                    own = Some(Hit {
                                        primitive: PrimitiveId(primitive),
                                        shape_hit,
                                    })
                                },
                            );
                        }
                        assert_eq!(found & 1 << lane != 0, closest.is_some(), "lane {lane}");
                        assert_eq!(hits[lane], own, "lane {lane}");
                        let end = closest.unwrap_or(ends[lane]);
                        assert_eq!(t_max[lane].to_bits(), end.to_bits(), "lane {lane}");
                        lanes_hit += usize::from(closest.is_some());
                    }
                    leaves += 1;
                    0
                },
            );
        }
        assert!(
            leaves > 500 && lanes_hit > 200,
            "{leaves} leaves, {lanes_hit} hits"
        );
    }

    #[test]
    fn searched_shapes_and_instances_keep_single_walks() {
        let mut rng = Rng::new(8);
        let mut objects = closed_form_scene(&mut rng, false);
        assert_eq!(World::new(&objects).walks_packets(), has_avx());
        assert!(!World::build(&objects, AccelKind::KdTree).packet_walk);
        let torus = Torus::new(1.0, 0.3).unwrap();
        objects.add_primitive(Shape::Torus(torus), MaterialId(0), Transform::IDENTITY);
        assert!(!World::new(&objects).packet_walk);
        let packets = camera_packets(&mut rng, 100, 0.01);
        assert_packets_agree(&objects, &packets);

        let mut instanced = closed_form_scene(&mut rng, false);
        let copy = instanced.add_mesh(instanced.meshes[0].clone());
        let moved = Transform::translate(Vec3::new(1.0, 0.5, -1.0)).unwrap();
        instanced.add_mesh_instance(copy, MaterialId(0), moved);
        assert!(!World::new(&instanced).packet_walk);
        assert_packets_agree(&instanced, &packets);
    }
}
