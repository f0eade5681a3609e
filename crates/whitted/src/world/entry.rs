//! What a structure's queries name, kept in the order they name it: one
//! [`Entry`] per position of a BVH's or kd-tree's index array (per slot for
//! the other structures), so that a leaf's triangles lie together in
//! memory, with their corners beside the number a hit reports.
//!
//! The leaf functions here serve both levels of the world: the top level
//! (shapes, triangles of meshes placed once, and whole instances) and each
//! instanced mesh's own structure (triangles only).

use std::ops::Range;

use crate::math::{Ray, Vec3};
use crate::shape::{FourLanes, Hits4, LANES};
use crate::shape::{Polygon, RayShear, ShapeHit, Sphere, plane_hit, watertight};

/// The margin of [`Entry::axis_missed`], relative to the sizes it adds.
const AXIAL_MARGIN: f64 = 1e-6;

/// The squared sine of the angle between a ray and an axis below which
/// [`Entry::axis_missed`] does not judge: the cross product's rounding, up
/// to a few times 1e-16 of the lengths' product, is then more than a
/// millionth of it.
const NEAR_AXIS: f64 = 1e-16;

/// What an entry's number names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub(super) enum EntryKind {
    /// A triangle whose corners are in the entry: tested right there.
    Triangle,
    /// A sphere without a transform, its centre and radius in the entry:
    /// tested right there too.
    Sphere,
    /// A polygon without a transform, its first vertex and unit normal in
    /// the entry: a ray that does not cross its plane in the interval is
    /// turned away right there, sparing the trip to the vertices and
    /// outline, three allocations away, for most rays that reach its leaf;
    /// for the others, the tables test only the outline, at the plane's
    /// `t` found here ([`Polygon::hit_on_plane`]).
    Polygon,
    /// A cylinder or a cone, in the entry as the ends of its axis and a
    /// bound on its points' distance from the axis: a ray whose line
    /// passes farther from the axis is turned away right there, the others
    /// are tested through the tables.
    Axial,
    /// A primitive tested through the world's tables (a shape).
    Primitive,
    /// A mesh instance, tested through its mesh's own structure.
    Instance,
    /// An instance of a definition, tested through the definition's world.
    Placed,
}

/// One position of a structure's index array: a number (a primitive's, a
/// triangle's in its mesh, or an instance's, as `kind` says) and, for a
/// triangle, its corners; for a sphere, its centre and radius (as the
/// first corner and the second's x), so that its test reads no other
/// table. The number shares the corners' 80 bytes, so a hit
/// reads it from the cache line its test read (docs/performance-log.md, world
/// entries and preparation, has the figures for this layout).
#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    /// What the entry names, by `kind`.
    pub(super) number: u32,
    /// How to test it.
    pub(super) kind: EntryKind,
    /// The triangle's corners, the sphere's centre and radius; zero for
    /// other entries.
    pub(super) corners: [Vec3; 3],
}

const _: () = assert!(size_of::<Entry>() == 80);

impl Entry {
    /// A triangle with these corners, reported as `number`.
    pub(super) fn triangle(number: u32, corners: [Vec3; 3]) -> Self {
        Self {
            number,
            kind: EntryKind::Triangle,
            corners,
        }
    }

    /// A sphere, reported as `number`.
    pub(super) fn sphere(number: u32, sphere: &Sphere) -> Self {
        Self {
            number,
            kind: EntryKind::Sphere,
            corners: [
                sphere.center(),
                Vec3::new(sphere.radius(), 0.0, 0.0),
                Vec3::ZERO,
            ],
        }
    }

    /// A polygon, reported as `number`, with the first vertex and unit
    /// normal its test starts from ([`Polygon::vertices`],
    /// [`Polygon::normal`]).
    pub(super) fn polygon(number: u32, polygon: &Polygon) -> Self {
        Self {
            number,
            kind: EntryKind::Polygon,
            corners: [polygon.vertices()[0], polygon.normal(), Vec3::ZERO],
        }
    }

    /// A cylinder or a cone, reported as `number`: points within `radius`
    /// of the segment from `base` to `top` (see [`Entry::axis_missed`]).
    /// Holds the base, the axis and, in the third corner, the reach and
    /// the near-axis threshold.
    pub(super) fn axial(number: u32, base: Vec3, top: Vec3, radius: f64) -> Self {
        let axis = top - base;
        // What `axis_missed` needs that does not depend on the ray: the
        // reach without the origin's part of the margin, and the least
        // squared length of a cross product with a unit direction that it
        // judges.
        let reach =
            radius + AXIAL_MARGIN * (radius + axis.abs().max_element() + base.abs().max_element());
        Self {
            number,
            kind: EntryKind::Axial,
            corners: [
                base,
                axis,
                Vec3::new(reach, NEAR_AXIS * axis.length_squared(), 0.0),
            ],
        }
    }

    /// An entry tested through the world's tables.
    pub(super) fn other(number: u32, kind: EntryKind) -> Self {
        Self {
            number,
            kind,
            corners: [Vec3::ZERO; 3],
        }
    }

    /// The corners, if the entry is a triangle.
    #[inline(always)]
    pub(super) fn corners(&self) -> Option<&[Vec3; 3]> {
        (self.kind == EntryKind::Triangle).then_some(&self.corners)
    }

    /// The entry hit by the query's ray closer than `t_max`, tested in
    /// place (a triangle or a sphere, and the polygons and cylinders or
    /// cones turned away there), or what is left to the world's tables: a
    /// polygon whose plane the ray crosses in the interval leaves only its
    /// outline, at the plane's `t`, so that the plane is not tested twice.
    #[inline(always)]
    pub(super) fn test_in_place(
        &self,
        query: &Query,
        t_max: f64,
    ) -> Result<Option<ShapeHit>, Rest> {
        match self.kind {
            EntryKind::Triangle => Ok(intersect_triangle(&self.corners, query, t_max)),
            EntryKind::Sphere => {
                let mut ray = *query.ray;
                ray.t_max = t_max;
                Ok(self.as_sphere().intersect(&ray))
            }
            EntryKind::Polygon => {
                let mut ray = *query.ray;
                ray.t_max = t_max;
                match plane_hit(self.corners[0], self.corners[1], &ray) {
                    Some(t) => Err(Rest::Outline(t)),
                    None => Ok(None),
                }
            }
            EntryKind::Axial if self.axis_missed(query.ray) => Ok(None),
            _ => Err(Rest::Test),
        }
    }

    /// Whether an axial entry's shape is surely missed by `ray`: its line
    /// passes farther from the axis's line than any point of the shape, by
    /// a margin far above the rounding of the shape's own test, which then
    /// finds no hit either. The margin is a millionth of the shape's size,
    /// of the ray origin's distance and of the coordinates (the axis's ends
    /// are rounded where they lie). Rays within 1e-8 radians of the axis's
    /// direction are never turned away: there the cross product below is
    /// mostly rounding, which the margin would not cover. Spares the trip
    /// through the primitive and transform tables for most rays that reach
    /// a slanted cylinder's loose box (measured: docs/performance-log.md,
    /// "polygons, cylinders and cones turned away in place").
    #[inline(always)]
    fn axis_missed(&self, ray: &Ray) -> bool {
        let [base, axis, fixed] = self.corners;
        let across = ray.dir.cross(axis);
        let across_squared = across.length_squared();
        // False for NaN too: such a ray is left to the tables.
        let judged = across_squared > fixed.y * ray.dir.length_squared();
        if !judged {
            return false;
        }
        let from_base = ray.origin - base;
        let reach = fixed.x + AXIAL_MARGIN * from_base.abs().max_element();
        let distance = from_base.dot(across);
        distance * distance > reach * reach * across_squared
    }

    /// Whether the entry lies in the query's ray interval, tested in place
    /// (a triangle or a sphere, and the polygons and cylinders or cones
    /// turned away there), or what is left to the world's tables, as
    /// [`Entry::test_in_place`] says it.
    #[inline(always)]
    pub(super) fn occlusion_in_place(&self, query: &Query) -> Result<bool, Rest> {
        match self.kind {
            EntryKind::Triangle => {
                Ok(intersect_triangle(&self.corners, query, query.ray.t_max).is_some())
            }
            EntryKind::Sphere => Ok(self.as_sphere().occluded(query.ray)),
            EntryKind::Polygon => match plane_hit(self.corners[0], self.corners[1], query.ray) {
                Some(t) => Err(Rest::Outline(t)),
                None => Ok(false),
            },
            EntryKind::Axial if self.axis_missed(query.ray) => Ok(false),
            _ => Err(Rest::Test),
        }
    }

    /// The sphere a [`EntryKind::Sphere`] entry holds.
    #[inline(always)]
    pub(super) fn as_sphere(&self) -> Sphere {
        Sphere::from_accepted(self.corners[0], self.corners[1].x)
    }
}

/// What an entry's test in place leaves to the world's tables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Rest {
    /// The whole test.
    Test,
    /// A polygon's outline test at `t`, where the ray crosses its plane in
    /// the interval ([`crate::shape::Polygon::hit_on_plane`]).
    Outline(f64),
}

/// A ray with what the triangle test needs of it, computed once per query
/// when the structure holds triangles (a world of other shapes does not pay
/// for it).
#[derive(Clone, Copy)]
pub(super) struct Query<'r> {
    /// The ray, in the space of the structure's entries.
    pub(super) ray: &'r Ray,
    shear: Option<RayShear>,
}

impl<'r> Query<'r> {
    /// A query for `ray`, with the shear precomputed if `triangles`.
    #[inline]
    pub(super) fn new(ray: &'r Ray, triangles: bool) -> Self {
        Self {
            ray,
            shear: triangles.then(|| RayShear::new(ray)),
        }
    }

    /// The ray's shear for the triangle test.
    #[inline]
    pub(super) fn shear(&self) -> RayShear {
        self.shear.unwrap_or_else(|| RayShear::new(self.ray))
    }
}

/// The triangle with these corners hit by the query's ray, closer than
/// `t_max`.
#[inline(always)]
pub(super) fn intersect_triangle(
    [p0, p1, p2]: &[Vec3; 3],
    query: &Query,
    t_max: f64,
) -> Option<ShapeHit> {
    let mut ray = *query.ray;
    ray.t_max = t_max;
    watertight(*p0, *p1, *p2, &ray, &query.shear())
}

/// The closest of `entries[range]` hit by the query's ray before `best`,
/// the closest hit so far (its `t`, and its number or `u32::MAX`; see
/// [`nearer`]): triangles and spheres here, other entries by
/// `other(entry, t_max, rest)` (what the test in place left, [`Rest`]),
/// which returns the number to report and the hit.
/// `found(number, hit)` is told of each nearer hit; returns the closest `t`.
/// Where the backend's lanes `L` have a four-sphere cull, runs of two to
/// four spheres are culled at once and only the spheres kept are tested,
/// one by one in order, so the answers are those of one by one. Triangles are tested one
/// at a time: tried testing runs of them four at a time as
/// [`leaf_occludes`] does: slower, see docs/performance-log.md (four-at-once
/// triangle test).
#[inline(always)]
pub(super) fn leaf_hit<L: FourLanes>(
    entries: &[Entry],
    range: Range<u32>,
    query: &Query,
    best: (f64, u32),
    mut other: impl FnMut(&Entry, f64, Rest) -> Option<(u32, ShapeHit)>,
    mut found: impl FnMut(u32, ShapeHit),
) -> Option<f64> {
    let (mut t_max, mut number_so_far) = best;
    let mut closest = None;
    // Tested to one ulp past the closest hit, so that a tie is seen and
    // goes to the lower number ([`nearer`]).
    let mut bound = t_max.next_up();
    let mut entry = range.start;
    while entry < range.end {
        let e = &entries[entry as usize];
        if L::ANY
            && e.kind == EntryKind::Sphere
            && let Some((run, mut mask)) = sphere_run::<L>(entries, entry, range.end, query, bound)
        {
            while mask != 0 {
                let e = &entries[(entry + mask.trailing_zeros()) as usize];
                let mut ray = *query.ray;
                ray.t_max = bound;
                if let Some(h) = e.as_sphere().intersect(&ray)
                    && nearer((h.t, e.number), (t_max, number_so_far))
                {
                    found(e.number, h);
                    (t_max, number_so_far, bound) = (h.t, e.number, h.t.next_up());
                    closest = Some(h.t);
                }
                mask &= mask - 1;
            }
            entry += run;
            continue;
        }
        let hit = match e.test_in_place(query, bound) {
            Ok(hit) => hit.map(|h| (e.number, h)),
            Err(rest) => other(e, bound, rest),
        };
        if let Some((number, h)) = hit
            && nearer((h.t, number), (t_max, number_so_far))
        {
            found(number, h);
            (t_max, number_so_far, bound) = (h.t, number, h.t.next_up());
            closest = Some(h.t);
        }
        entry += 1;
    }
    closest
}

/// Whether a hit at `t` on primitive `number` comes before the closest so
/// far: nearer, or at the same parameter with a lower number. The closest
/// hit is then the least `(t, number)` whatever order a structure visits
/// primitives in, so every structure finds the same one (brute force, in
/// number order, keeps the first of a tie).
#[inline(always)]
pub(super) fn nearer((t, number): (f64, u32), (closest, closest_number): (f64, u32)) -> bool {
    t < closest || (t == closest && number < closest_number)
}

/// An entry of `entries[range]` that lies in the query's ray interval (the
/// first one found), if any: triangles here, other entries when
/// `other(entry, rest)` says so (`rest`: what the test in place left).
/// Where the backend's lanes `L` have four-lane tests, runs of two to four
/// triangles are tested at once, and runs of two to four spheres culled at
/// once, with the same answers as one by one.
#[inline(always)]
pub(super) fn leaf_occludes<L: FourLanes>(
    entries: &[Entry],
    range: Range<u32>,
    query: &Query,
    other: impl FnMut(&Entry, Rest) -> bool,
) -> Option<u32> {
    leaf_meets::<L>(entries, range, query, other, |_| true)
}

/// [`leaf_occludes`] that shows `stops` each entry found in the interval,
/// in order, and ends at the first one it says stops the walk, returning
/// it; entries that do not are only shown.
#[inline(always)]
pub(super) fn leaf_meets<L: FourLanes>(
    entries: &[Entry],
    range: Range<u32>,
    query: &Query,
    mut other: impl FnMut(&Entry, Rest) -> bool,
    mut stops: impl FnMut(u32) -> bool,
) -> Option<u32> {
    let mut entry = range.start;
    while entry < range.end {
        if L::ANY
            && let Some((run, hits)) = triangle_run::<L>(entries, entry, range.end, query)
        {
            let mut mask = hits.mask;
            while mask != 0 {
                let hit = entry + mask.trailing_zeros();
                if stops(hit) {
                    return Some(hit);
                }
                mask &= mask - 1;
            }
            entry += run;
            continue;
        }
        if L::ANY
            && entries[entry as usize].kind == EntryKind::Sphere
            && let Some((run, mut mask)) =
                sphere_run::<L>(entries, entry, range.end, query, query.ray.t_max)
        {
            while mask != 0 {
                let hit = entry + mask.trailing_zeros();
                if entries[hit as usize].as_sphere().occluded(query.ray) && stops(hit) {
                    return Some(hit);
                }
                mask &= mask - 1;
            }
            entry += run;
            continue;
        }
        let e = &entries[entry as usize];
        let meets = match e.occlusion_in_place(query) {
            Ok(meets) => meets,
            Err(rest) => other(e, rest),
        };
        if meets && stops(entry) {
            return Some(entry);
        }
        entry += 1;
    }
    None
}

/// The run of two to [`LANES`] entries of `kind` that starts at `entry`
/// (and ends before `end`): its length and each lane's corners, lane `i`
/// for entry `entry + i`. Lanes past the run repeat the first entry; their
/// answers are to be masked out. `None` without such a run.
#[inline(always)]
fn run_of(
    entries: &[Entry],
    entry: u32,
    end: u32,
    kind: EntryKind,
) -> Option<(u32, [&[Vec3; 3]; LANES])> {
    let available = (end - entry).min(LANES as u32) as usize;
    let entries = &entries[entry as usize..entry as usize + available];
    let run = entries.iter().take_while(|e| e.kind == kind).count();
    if run < 2 {
        return None;
    }
    let lane = |i: usize| &entries[if i < run { i } else { 0 }].corners;
    Some((run as u32, [lane(0), lane(1), lane(2), lane(3)]))
}

/// The run of two to [`LANES`] triangles that starts at `entry` (and ends
/// before `end`), tested at once against the query's ray: its length and
/// the hits, lane `i` for entry `entry + i`. `None` without such a run,
/// or where the lanes `L` have no four-triangle test. Called only in a
/// kernel whose lanes are `L`.
#[inline(always)]
fn triangle_run<L: FourLanes>(
    entries: &[Entry],
    entry: u32,
    end: u32,
    query: &Query,
) -> Option<(u32, Hits4)> {
    let (run, lanes) = run_of(entries, entry, end, EntryKind::Triangle)?;
    // SAFETY: called in a kernel whose lanes are `L`, so the processor
    // runs their instruction set.
    let hits = unsafe { L::triangles(lanes, query.ray, &query.shear(), query.ray.t_max) }?;
    let mask = hits.mask & ((1 << run) - 1);
    Some((run, Hits4 { mask, ..hits }))
}

/// The run of two to [`LANES`] spheres that starts at `entry` (and ends
/// before `end`), culled at once for the query's ray ending at `t_max`: its
/// length and the spheres kept, bit `i` for entry `entry + i`. A sphere not
/// kept has no hit closer than `t_max` or any smaller end. `None` without
/// such a run, or where the lanes `L` have no four-sphere cull. Called
/// only in a kernel whose lanes are `L`.
#[inline(always)]
fn sphere_run<L: FourLanes>(
    entries: &[Entry],
    entry: u32,
    end: u32,
    query: &Query,
    t_max: f64,
) -> Option<(u32, u32)> {
    let (run, lanes) = run_of(entries, entry, end, EntryKind::Sphere)?;
    let centers = lanes.map(|corners| &corners[0]);
    let radii = lanes.map(|corners| &corners[1].x);
    // SAFETY: as in `triangle_run`.
    let mask = unsafe { L::sphere_candidates(centers, radii, query.ray, t_max) }?;
    Some((run, mask & ((1 << run) - 1)))
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::math::test_support::has_avx_or_skip_allowed;
    use crate::shape::{AvxLanes, OneByOne};

    /// A leaf of overlapping spheres with, now and then, a triangle or an
    /// entry tested through the tables among them, so that runs of every
    /// length from one to beyond four occur.
    fn leaf(rng: &mut Rng) -> Vec<Entry> {
        let size = 1 + rng.below(9);
        (0..size)
            .map(|number| match rng.below(8) {
                0 => Entry::triangle(
                    number,
                    [0, 1, 2].map(|_| rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0))),
                ),
                1 => Entry::other(number, EntryKind::Primitive),
                _ => Entry::sphere(
                    number,
                    &Sphere::new(
                        rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0)),
                        0.05 + 2.0 * rng.uniform(),
                    )
                    .unwrap(),
                ),
            })
            .collect()
    }

    #[test]
    fn culling_runs_of_spheres_four_at_a_time_changes_no_answer() {
        if !has_avx_or_skip_allowed() {
            return;
        }
        let mut rng = Rng::new(21);
        let (mut hits, mut culled_runs) = (0, 0);
        for _ in 0..20_000 {
            let entries = leaf(&mut rng);
            let origin = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            let mut ray = Ray::new(origin, rng.unit_vector() * (0.1 + 3.0 * rng.uniform()));
            ray.t_max = [f64::INFINITY, 1.0, 0.2][rng.below(3) as usize];
            let query = Query::new(&ray, true);
            // Entries tested through the tables hit at a fixed distance.
            let other = |e: &Entry, t_max: f64, _: Rest| {
                (0.5 < t_max).then_some((e.number, ShapeHit::at(0.5)))
            };
            fn closest<L: FourLanes>(
                entries: &[Entry],
                query: &Query,
                other: impl FnMut(&Entry, f64, Rest) -> Option<(u32, ShapeHit)>,
            ) -> (Option<u64>, Vec<(u32, u64)>) {
                let mut found = Vec::new();
                let t = leaf_hit::<L>(
                    entries,
                    0..entries.len() as u32,
                    query,
                    (query.ray.t_max, u32::MAX),
                    other,
                    |n, h| found.push((n, h.t.to_bits())),
                );
                (t.map(f64::to_bits), found)
            }
            let one_by_one = closest::<OneByOne>(&entries, &query, other);
            assert_eq!(
                closest::<AvxLanes>(&entries, &query, other),
                one_by_one,
                "{entries:?} {ray:?}"
            );
            hits += usize::from(one_by_one.0.is_some());
            let meets = |e: &Entry, _: Rest| e.number.is_multiple_of(2) && 0.5 < ray.t_max;
            fn first<L: FourLanes>(
                entries: &[Entry],
                query: &Query,
                meets: impl FnMut(&Entry, Rest) -> bool,
            ) -> (Option<u32>, Vec<u32>) {
                let mut shown = Vec::new();
                let range = 0..entries.len() as u32;
                let stop = leaf_meets::<L>(entries, range, query, meets, |n| {
                    shown.push(n);
                    n % 3 == 2
                });
                (stop, shown)
            }
            assert_eq!(
                first::<AvxLanes>(&entries, &query, meets),
                first::<OneByOne>(&entries, &query, meets),
                "{entries:?} {ray:?}"
            );
            culled_runs += usize::from(
                entries
                    .windows(2)
                    .any(|w| w.iter().all(|e| e.kind == EntryKind::Sphere)),
            );
        }
        assert!(hits > 5_000 && culled_runs > 10_000, "{hits} {culled_runs}");
    }
}
