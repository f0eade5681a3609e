//! Shadow rays in worlds where some surfaces let light through. The
//! integrator must then walk such a ray from surface to surface, scaling
//! the light at each crossing; but most shadow rays meet an opaque surface
//! or nothing at all, and one any-hit walk tells those apart: it stops at
//! the first entry whose material lets nothing through, and only notes the
//! others. Only a ray that crosses such surfaces and nothing opaque needs
//! the surface-to-surface walk, and the any-hit walk lists the entries it
//! met ([`PassedEntries`]): each step of that walk then tests those alone
//! instead of walking the whole structure again.

use super::lanes::LanesOf;
use std::ops::Range;

use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::{AnyLeaves, Backend, QueryContext};
use crate::math::Ray;
use crate::shape::{Shape, ShapeHit};
use crate::world::entry::{Entry, EntryKind, Query, leaf_meets};
use crate::world::{Hit, MaterialId, PrimitiveId, PrimitiveRef, ShadowHint, World};

/// Most entries a [`PassedEntries`] lists; a shadow ray that meets more
/// takes whole-structure steps.
const PASSED_CAPACITY: usize = 12;

/// How near, relative to their parameter, two listed entries' hits must be
/// for [`World::intersect_passed`] (and [`World::intersect_from`]) to
/// leave the choice to the whole walk:
/// a billionth, far above the few ulps by which the walk's box culls
/// (node boxes, a grid's or kd-tree's primitive boxes and cell exits) can
/// keep a hit that lies just outside its box and turn one just inside away.
const NEAR_TIE: f64 = 1e-9;

/// Which of a world's entries stop light: those every hit of which shows a
/// material that lets nothing through; and, of the others, which the
/// steps of a shadow ray may test alone ([`World::opaque_entries`],
/// [`PassedEntries`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OpaqueEntries {
    /// Per entry of the structure, in the world's entry order.
    entries: Vec<Passage>,
    /// Per unbounded entry.
    unbounded: Vec<Passage>,
}

/// What an entry does to a shadow ray that meets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Passage {
    /// Stops it: no light arrives.
    Stops,
    /// Lets light through, at a parameter its test finds by a closed
    /// formula (the same whatever interval it is tested under): listed in
    /// [`PassedEntries`].
    Listed,
    /// Lets light through, at a parameter a search finds (a Bézier patch,
    /// CSG): which of two nearby roots it reports may depend on the
    /// interval it is tested under, and so on the order of the tests, so
    /// the steps walk the whole structure as the plain query does.
    Searched,
}

/// What lies along a shadow ray's interval ([`World::shadow_path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowPath {
    /// Nothing: all the light arrives.
    Clear,
    /// Something opaque: no light arrives, whatever else lies in the way.
    Blocked,
    /// Only surfaces that may let light through, on these entries: the
    /// light that arrives is what each lets through, found by walking from
    /// one to the next ([`World::intersect_passed`]).
    Crossed(PassedEntries),
}

/// The entries letting light through that a shadow ray's interval meets,
/// as the any-hit walk of [`World::shadow_path`] found them (in its order),
/// or [`PassedEntries::UNLISTED`] when they are not known: more than
/// [`PASSED_CAPACITY`] of them, or one whose hit a search finds.
///
/// The same list holds what reaches into a glass sphere
/// ([`crate::world::Interiors`]).
///
/// The surface-to-surface walk that follows steps along the same line
/// towards the same end, so its hits are on these entries: testing them
/// alone answers as a walk of the whole structure would, where one hit is
/// clearly the closest ([`World::intersect_passed`] leaves near ties to
/// the walk). The one exception is a step ray, which leaves each surface a
/// few rounding errors off the line, grazing the edge of a shape that the
/// line itself missed by less than that (the same uncertainty a ray's own
/// rounding already has).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassedEntries {
    /// Positions in the world's entries.
    entries: [u32; PASSED_CAPACITY],
    /// How many of `entries` are listed; more than the capacity when the
    /// list is not known.
    len: usize,
    /// The unbounded entries met, bit `i` for entry `i`.
    unbounded: u32,
}

impl PassedEntries {
    /// Entries not known: every step walks the whole structure.
    pub const UNLISTED: Self = Self {
        entries: [0; PASSED_CAPACITY],
        len: PASSED_CAPACITY + 1,
        unbounded: 0,
    };

    /// No entry yet.
    pub(super) const EMPTY: Self = Self {
        entries: [0; PASSED_CAPACITY],
        len: 0,
        unbounded: 0,
    };

    /// Whether the entries are listed.
    pub fn is_listed(&self) -> bool {
        self.len <= PASSED_CAPACITY
    }

    /// The listed entries' positions.
    pub(super) fn entries(&self) -> impl Iterator<Item = u32> + '_ {
        self.entries[..self.len.min(PASSED_CAPACITY)]
            .iter()
            .copied()
    }

    /// The unbounded entries listed, bit `i` for entry `i`.
    #[cfg(test)]
    pub(super) fn unbounded_bits(&self) -> u32 {
        self.unbounded
    }

    /// Whether no entry was met.
    pub(super) fn is_empty(&self) -> bool {
        self.len == 0 && self.unbounded == 0
    }

    /// Adds the entry at position `entry` of `entries`, unless an entry of
    /// the same primitive is listed (a kd-tree names a primitive in every
    /// leaf it spans); past the capacity the list is
    /// [`PassedEntries::UNLISTED`].
    pub(super) fn push(&mut self, entry: u32, entries: &[Entry]) {
        let number = entries[entry as usize].number;
        let listed = &self.entries[..self.len.min(PASSED_CAPACITY)];
        if listed.iter().any(|&e| entries[e as usize].number == number) {
            return;
        }
        if self.len < PASSED_CAPACITY {
            self.entries[self.len] = entry;
            self.len += 1;
        } else {
            *self = Self::UNLISTED;
        }
    }

    /// Adds unbounded entry `i`; one past the bits makes the list
    /// [`PassedEntries::UNLISTED`].
    pub(super) fn push_unbounded(&mut self, i: usize) {
        if i < u32::BITS as usize {
            self.unbounded |= 1 << i;
        } else {
            *self = Self::UNLISTED;
        }
    }
}

impl World<'_> {
    /// Which entries stop light, given which materials let nothing through
    /// (`opaque`, by material id): an entry does when every hit on it shows
    /// one such material (a shape's own or a placed mesh's). A CSG object,
    /// whose children may show other materials, counts as letting light
    /// through. `None` for a world with instances, whose materials an
    /// enclosing instance may replace: its shadow rays take the
    /// surface-to-surface walk.
    pub fn opaque_entries(&self, opaque: &[bool]) -> Option<OpaqueEntries> {
        if self.instance_count != 0 {
            return None;
        }
        let passage = |e: &Entry| {
            let stops = self
                .entry_material(e)
                .is_some_and(|m| opaque.get(m.0 as usize) == Some(&true));
            match (stops, self.closed_form(e)) {
                (true, _) => Passage::Stops,
                (false, true) => Passage::Listed,
                (false, false) => Passage::Searched,
            }
        };
        Some(OpaqueEntries {
            entries: self.entries.iter().map(passage).collect(),
            unbounded: self.unbounded.iter().map(passage).collect(),
        })
    }

    /// True when entry `e`'s hits come from a closed formula
    /// ([`Shape::closed_form`]): not an instance, whose walk may stop at
    /// either of two tied hits depending on the interval.
    pub(super) fn closed_form(&self, e: &Entry) -> bool {
        match e.kind {
            EntryKind::Primitive => self.shapes[e.number as usize].shape.closed_form(),
            EntryKind::Instance | EntryKind::Placed => false,
            _ => true,
        }
    }

    /// The one material every hit on entry `e` shows, if there is one.
    fn entry_material(&self, e: &Entry) -> Option<MaterialId> {
        if !matches!(
            e.kind,
            EntryKind::Triangle
                | EntryKind::Sphere
                | EntryKind::Polygon
                | EntryKind::Axial
                | EntryKind::Primitive
        ) {
            return None;
        }
        match self.primitive_ref(e.number) {
            PrimitiveRef::Shape(i) => {
                let p = &self.objects.primitives[i as usize];
                (!matches!(p.shape, Shape::Csg(_))).then_some(p.material)
            }
            PrimitiveRef::Triangle { instance, .. } => {
                Some(self.objects.mesh_instances[instance as usize].material)
            }
            PrimitiveRef::Placed { .. } => None,
        }
    }

    /// What lies in `ray`'s interval, told apart by `opaque` (this world's
    /// [`World::opaque_entries`]): [`ShadowPath::Blocked`] as soon as an
    /// entry that stops light is found, [`ShadowPath::Crossed`] when only
    /// others are, [`ShadowPath::Clear`] when nothing is, as
    /// [`World::occluded`] would say of the same ray. The entry in `hint`
    /// is tried first (the shadow cache, as [`World::occluded_hinted`]
    /// uses it), and the entry that blocked is left in it.
    pub fn shadow_path(
        &self,
        ray: &Ray,
        opaque: &OpaqueEntries,
        hint: &mut ShadowHint,
    ) -> ShadowPath {
        let query = Query::new(ray, self.has_triangles);
        // A hint left by another query may name any entry: only one that
        // stops light can answer for the walk.
        if opaque.entries.get(hint.0 as usize) == Some(&Passage::Stops)
            && self.hint_blocks(*hint, &query)
        {
            return ShadowPath::Blocked;
        }
        *hint = ShadowHint::NONE;
        let mut passed = PassedEntries::EMPTY;
        for (i, (e, &passage)) in self.unbounded.iter().zip(&opaque.unbounded).enumerate() {
            if self.shape_occludes(e.number, &query) {
                match passage {
                    Passage::Stops => return ShadowPath::Blocked,
                    Passage::Listed => passed.push_unbounded(i),
                    Passage::Searched => passed = PassedEntries::UNLISTED,
                }
            }
        }
        /// The walk as a kernel's task.
        struct Walk<'q, 'a> {
            world: &'q World<'a>,
            ray: &'q Ray,
            leaves: PassingLeaves<'q, 'a>,
        }
        impl KernelTask for Walk<'_, '_> {
            type Output = bool;
            #[inline(always)]
            fn run<K: Kernel>(self) -> bool {
                let mut ctx = QueryContext::default();
                self.world
                    .accel
                    .any_with::<K>(self.ray, &mut ctx, self.leaves)
            }
        }
        let leaves = PassingLeaves {
            world: self,
            query: &query,
            opaque,
            passed: &mut passed,
            hint,
        };
        let walk = Walk {
            world: self,
            ray,
            leaves,
        };
        let blocked = kernel::run(Backend::current(), walk);
        if blocked {
            ShadowPath::Blocked
        } else if !passed.is_empty() {
            ShadowPath::Crossed(passed)
        } else {
            ShadowPath::Clear
        }
    }

    /// The closest hit in `ray`'s interval among the entries `passed`
    /// lists (a shadow ray's, found by [`World::shadow_path`] for a ray
    /// along the same line), each with the closest-hit walk's own test of
    /// the entry; [`World::intersect`] when they are not listed, or when
    /// two primitives are hit within [`NEAR_TIE`] of each other: which of
    /// those the walk keeps depends on the order it visits them and on its
    /// box culls, which the list cannot tell.
    pub fn intersect_passed(&self, ray: &Ray, passed: &PassedEntries) -> Option<Hit> {
        if !passed.is_listed() {
            return self.intersect(ray);
        }
        self.closest_listed(ray, passed, self.has_triangles)
            .unwrap_or_else(|NearTie| self.intersect(ray))
    }

    /// The closest hit in `ray`'s interval among the entries `listed`
    /// lists (which it does), each tested as the closest-hit walk tests
    /// it, in the list's order; [`NearTie`] when two primitives are hit
    /// within [`NEAR_TIE`] of each other. The triangle tests' shear of the
    /// ray is made once up front if `triangles`, else for each.
    #[inline]
    pub(super) fn closest_listed(
        &self,
        ray: &Ray,
        listed: &PassedEntries,
        triangles: bool,
    ) -> Result<Option<Hit>, NearTie> {
        let query = Query::new(ray, triangles);
        let mut inner = QueryContext::default();
        let mut best: Option<Hit> = None;
        for e in self.listed(listed) {
            // Past the closest so far by the tie window, to see a near tie.
            let t_max = best.map_or(ray.t_max, |b| near_tie(b.shape_hit.t).1);
            let Some((primitive, shape_hit)) = self.test_listed(e, &query, t_max, &mut inner)
            else {
                continue;
            };
            if let Some(b) = best
                && shape_hit.t >= near_tie(b.shape_hit.t).0
            {
                if primitive == b.primitive.0 {
                    continue;
                }
                return Err(NearTie);
            }
            best = Some(Hit {
                primitive: PrimitiveId(primitive),
                shape_hit,
            });
        }
        Ok(best)
    }

    /// The entries `listed` names: its unbounded ones, then the others in
    /// the walk's order.
    fn listed<'s>(&'s self, listed: &'s PassedEntries) -> impl Iterator<Item = &'s Entry> {
        let unbounded = set_bits(listed.unbounded).map(|i| &self.unbounded[i]);
        let entries = listed.entries().map(|entry| &self.entries[entry as usize]);
        unbounded.chain(entries)
    }

    /// Entry `e`'s closest hit in the interval of `query`'s ray ending at
    /// `t_max`, as the closest-hit walk tests it: in place, then through
    /// the tables.
    #[inline]
    fn test_listed(
        &self,
        e: &Entry,
        query: &Query,
        t_max: f64,
        inner: &mut QueryContext,
    ) -> Option<(u32, ShapeHit)> {
        match e.test_in_place(query, t_max) {
            Ok(hit) => hit.map(|h| (e.number, h)),
            Err(rest) => self.intersect_other(&self.definitions, e, (query, t_max, rest), inner),
        }
    }

    /// True when every hit on entry `e` lies in one plane: a line crosses
    /// it once at most ([`Shape::is_flat`]).
    fn is_flat(&self, e: &Entry) -> bool {
        match e.kind {
            EntryKind::Triangle | EntryKind::Polygon => true,
            EntryKind::Primitive => self.shapes[e.number as usize].shape.is_flat(),
            _ => false,
        }
    }
}

/// Where a shadow ray crosses the surfaces a [`PassedEntries`] lists,
/// nearest first ([`World::shadow_crossings`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowCrossings {
    /// The crossings, the first `len` of them sorted by `t`.
    crossings: [ShadowCrossing; Self::CAPACITY],
    /// How many there are.
    len: usize,
}

/// One place where a shadow ray crosses a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowCrossing {
    /// The ray parameter.
    pub t: f64,
    /// The primitive crossed.
    pub primitive: PrimitiveId,
    /// Its material.
    pub material: MaterialId,
}

impl ShadowCrossings {
    /// Most crossings it holds: four spheres' two sides, or eight flat
    /// surfaces. A shadow ray that crosses more takes the
    /// surface-to-surface walk; the list is kept small, as one is made and
    /// copied for every shadow ray that crosses glass.
    pub const CAPACITY: usize = 8;

    /// None yet.
    const EMPTY: Self = Self {
        crossings: [ShadowCrossing {
            t: 0.0,
            primitive: PrimitiveId(0),
            material: MaterialId(0),
        }; Self::CAPACITY],
        len: 0,
    };

    /// The crossings, nearest first.
    pub fn iter(&self) -> impl Iterator<Item = &ShadowCrossing> {
        self.crossings[..self.len].iter()
    }

    /// Adds `crossing` in its place along the ray; false, leaving the
    /// answer to the walk, when the list is full or the crossing lies
    /// within [`NEAR_TIE`] of one of another primitive: the walk's step
    /// leaves the first of two such surfaces a rounding error past both,
    /// and so crosses one of them only.
    fn insert(&mut self, crossing: ShadowCrossing) -> bool {
        let tied = |c: &ShadowCrossing| {
            let (low, high) = (c.t.min(crossing.t), c.t.max(crossing.t));
            high < near_tie(low).1 && c.primitive != crossing.primitive
        };
        if self.len == Self::CAPACITY || self.iter().any(tied) {
            return false;
        }
        let mut at = self.len;
        while at > 0 && self.crossings[at - 1].t > crossing.t {
            self.crossings[at] = self.crossings[at - 1];
            at -= 1;
        }
        self.crossings[at] = crossing;
        self.len += 1;
        true
    }
}

impl World<'_> {
    /// Where `ray`'s interval crosses the entries `passed` lists (a shadow
    /// ray's, found by [`World::shadow_path`] for the same ray), nearest
    /// first: the hits that the surface-to-surface walk steps through,
    /// each interval starting at the hit before, found all at once along
    /// `ray` itself. A sphere gives both its roots ([`Sphere::crossings`]);
    /// a flat entry (a triangle, polygon, plane, parallelogram or disk,
    /// [`Shape::is_flat`]) its one hit, found by the walk's own test of
    /// it. `None` when the list is not known or names another kind of
    /// entry, when two primitives' crossings lie within [`NEAR_TIE`] of
    /// each other (the walk's offset origins then cross one of them only)
    /// or one lies that near the ray's end, or when there are more than
    /// [`ShadowCrossings::CAPACITY`].
    ///
    /// [`Sphere::crossings`]: crate::shape::Sphere::crossings
    pub fn shadow_crossings(&self, ray: &Ray, passed: &PassedEntries) -> Option<ShadowCrossings> {
        if !passed.is_listed() {
            return None;
        }
        // A triangle's shear is made where it is tested: most lists hold
        // one triangle or none.
        let query = Query::new(ray, false);
        let mut inner = QueryContext::default();
        let mut crossings = ShadowCrossings::EMPTY;
        for e in self.listed(passed) {
            let material = self.entry_material(e)?;
            let mut add = |t: f64, primitive: u32| {
                crossings.insert(ShadowCrossing {
                    t,
                    primitive: PrimitiveId(primitive),
                    material,
                })
            };
            if e.kind == EntryKind::Sphere {
                for t in e.as_sphere().crossings(ray) {
                    if !add(t, e.number) {
                        return None;
                    }
                }
            } else if !self.is_flat(e) {
                return None;
            } else if let Some((primitive, hit)) =
                self.test_listed(e, &query, ray.t_max, &mut inner)
                && !add(hit.t, primitive)
            {
                return None;
            }
        }
        // A crossing at the ray's end (a light in a clear surface) is one
        // that the walk's steps, whose ends are worked out again from
        // each offset origin, may or may not reach.
        let last = crossings.iter().last();
        if last.is_some_and(|c| c.t >= near_tie(ray.t_max).0) {
            return None;
        }
        Some(crossings)
    }
}

/// Two listed primitives hit within [`NEAR_TIE`] of each other: the walk
/// decides between them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct NearTie;

/// The bounds of the window around a hit at parameter `t` (positive)
/// within which another hit is a near tie ([`NEAR_TIE`]): from `lower` up
/// to, not including, `upper`.
pub(super) fn near_tie(t: f64) -> (f64, f64) {
    let slack = NEAR_TIE * t;
    ((t - slack).min(t), (t + slack).max(t.next_up()))
}

/// The positions of the bits set in `bits`, lowest first.
fn set_bits(mut bits: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            i
        })
    })
}

/// The leaves of [`World::shadow_path`]'s walk: every entry found in the
/// interval is told apart by `opaque`; one that stops light ends the walk
/// (and is left in `hint`), the others are listed in `passed`.
struct PassingLeaves<'q, 'a> {
    world: &'q World<'a>,
    query: &'q Query<'q>,
    opaque: &'q OpaqueEntries,
    passed: &'q mut PassedEntries,
    hint: &'q mut ShadowHint,
}

impl AnyLeaves for PassingLeaves<'_, '_> {
    #[inline(always)]
    fn occludes<K: Kernel>(&mut self, range: Range<u32>) -> bool {
        let (world, query, opaque) = (self.world, self.query, self.opaque);
        let passed = &mut *self.passed;
        let blocker = leaf_meets::<LanesOf<K>>(
            &world.entries,
            range,
            query,
            |e, rest| world.rest_occludes(e.number, query, rest),
            |entry| match opaque.entries[entry as usize] {
                Passage::Stops => true,
                Passage::Listed => {
                    passed.push(entry, &world.entries);
                    false
                }
                Passage::Searched => {
                    *passed = PassedEntries::UNLISTED;
                    false
                }
            },
        );
        if let Some(entry) = blocker {
            *self.hint = ShadowHint(entry);
        }
        blocker.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::math::random::Rng;
    use crate::math::{Transform, Vec3};
    use crate::shape::{Cylinder, Disk, Parallelogram, Plane, Polygon, Sphere};
    use crate::world::Objects;
    use crate::world::{scattered_triangles, turned_square};

    /// Spheres of two materials (0 opaque, 1 clear), a mesh of scattered
    /// triangles of each, and a plane of the clear one.
    fn mixed_scene(rng: &mut Rng) -> Objects {
        let mut objects = Objects::default();
        for i in 0..150 {
            let centre = 10.0 * (rng.unit_vector() * rng.uniform());
            let sphere = Sphere::new(centre, 0.2 + 0.8 * rng.uniform()).unwrap();
            objects.add_primitive(
                Shape::Sphere(sphere),
                MaterialId(i % 2),
                Transform::IDENTITY,
            );
        }
        for material in 0..2 {
            let mesh = objects.add_mesh(scattered_triangles(rng, 200, 10.0));
            objects.add_mesh_instance(mesh, MaterialId(material), Transform::IDENTITY);
        }
        // Polygons (tested in place and through the tables) and moved
        // cylinders (through the tables), of both materials.
        for i in 0..60 {
            let centre = 10.0 * (rng.unit_vector() * rng.uniform());
            objects.add_primitive(
                Shape::Polygon(turned_square(rng, centre)),
                MaterialId(i % 2),
                Transform::IDENTITY,
            );
            let cylinder = Cylinder::new(0.3 + 0.3 * rng.uniform(), 1.5, i % 4 < 2).unwrap();
            let moved = 10.0 * (rng.unit_vector() * rng.uniform());
            objects.add_primitive(
                Shape::Cylinder(cylinder),
                MaterialId(i % 2),
                Transform::translate(moved).unwrap(),
            );
        }
        let floor = Plane::new(Vec3::new(0.0, -11.0, 0.0), Vec3::Y).unwrap();
        objects.add_primitive(Shape::Plane(floor), MaterialId(1), Transform::IDENTITY);
        objects
    }

    /// What the surface-to-surface walk finds along `ray`, each step's
    /// closest hit found by `step`: whether it meets something opaque
    /// (material 0), and the hits up to that.
    fn walk(
        world: &World<'_>,
        ray: &Ray,
        step: impl Fn(&Ray) -> Option<Hit>,
    ) -> (PathKind, Vec<Hit>) {
        let mut ray = *ray;
        let mut hits = Vec::new();
        while let Some(hit) = step(&ray) {
            hits.push(hit);
            if world.surface(&ray, &hit).material == MaterialId(0) {
                return (PathKind::Blocked, hits);
            }
            ray.t_min = hit.shape_hit.t;
        }
        let kind = if hits.is_empty() {
            PathKind::Clear
        } else {
            PathKind::Crossed
        };
        (kind, hits)
    }

    /// A shadow ray from a random point within `reach` of the origin to a
    /// random light near `(3, light_y, -4)`.
    fn shadow_ray(rng: &mut Rng, reach: f64, light_y: f64) -> Ray {
        let from = reach * rng.unit_vector() * rng.uniform();
        let light = Vec3::new(3.0, light_y, -4.0) + 4.0 * rng.unit_vector();
        Ray::segment(from, (light - from).normalize(), (light - from).length())
    }

    /// A [`ShadowPath`] without its entries.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum PathKind {
        Clear,
        Blocked,
        Crossed,
    }

    fn kind_of(path: ShadowPath) -> PathKind {
        match path {
            ShadowPath::Clear => PathKind::Clear,
            ShadowPath::Blocked => PathKind::Blocked,
            ShadowPath::Crossed(_) => PathKind::Crossed,
        }
    }

    #[test]
    fn the_any_hit_walk_tells_blocked_crossed_and_clear_as_the_surface_walk_does() {
        let mut rng = Rng::new(11);
        let objects = mixed_scene(&mut rng);
        for kind in [
            AccelKind::Bvh,
            AccelKind::KdTree,
            AccelKind::Grid,
            AccelKind::Linear,
        ] {
            let world = World::build(&objects, kind);
            let opaque = world.opaque_entries(&[true, false]).unwrap();
            let mut seen = [0; 3];
            let mut hint = ShadowHint::NONE;
            for _ in 0..1500 {
                let ray = shadow_ray(&mut rng, 12.0, 20.0);
                let path = world.shadow_path(&ray, &opaque, &mut ShadowHint::default());
                assert_eq!(world.shadow_path(&ray, &opaque, &mut hint), path, "hinted");
                let (expected, _) = walk(&world, &ray, |r| world.intersect(r));
                assert_eq!(kind_of(path), expected, "{kind:?} {ray:?}");
                assert_eq!(path != ShadowPath::Clear, world.occluded(&ray), "{kind:?}");
                seen[expected as usize] += 1;
            }
            assert!(seen.iter().all(|&n| n > 100), "{kind:?}: {seen:?}");
        }
    }

    #[test]
    fn stepping_through_the_entries_passed_finds_the_hits_of_whole_walks() {
        let mut rng = Rng::new(13);
        let objects = mixed_scene(&mut rng);
        for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
            let world = World::build(&objects, kind);
            let opaque = world.opaque_entries(&[true, false]).unwrap();
            // Crossed paths listed, those with two hits or more, those
            // through the unbounded floor, those through a polygon or a
            // cylinder.
            let mut seen = [0; 4];
            for i in 0..3000 {
                // Lights above and below the floor at y = -11.
                let ray = shadow_ray(&mut rng, 12.0, if i % 2 == 0 { 20.0 } else { -20.0 });
                let ShadowPath::Crossed(passed) =
                    world.shadow_path(&ray, &opaque, &mut ShadowHint::default())
                else {
                    continue;
                };
                let (_, whole) = walk(&world, &ray, |r| world.intersect(r));
                let (_, listed) = walk(&world, &ray, |r| world.intersect_passed(r, &passed));
                assert_eq!(listed, whole, "{kind:?} {ray:?}");
                seen[0] += usize::from(passed.is_listed());
                seen[1] += usize::from(whole.len() >= 2);
                seen[2] += usize::from(whole.iter().any(|h| h.primitive.0 == 270));
                seen[3] += usize::from(whole.iter().any(|h| (150..270).contains(&h.primitive.0)));
            }
            assert!(seen.iter().all(|&n| n > 50), "{kind:?}: {seen:?}");
        }
    }

    #[test]
    fn crossings_are_the_hits_of_the_surface_walk() {
        // Overlapping spheres, a triangle mesh, polygons, parallelograms
        // and disks (moved, turned and stretched), of materials 0 (opaque),
        // 1 and 2 (clear); a
        // clear floor plane (unbounded); and clear cylinders, whose
        // crossings are left to the walk.
        let mut rng = Rng::new(17);
        let mut objects = Objects::default();
        let material = |i: usize| MaterialId([0, 1, 2][i % 3]);
        for i in 0..120 {
            let centre = 8.0 * (rng.unit_vector() * rng.uniform());
            let sphere = Sphere::new(centre, 0.3 + 1.2 * rng.uniform()).unwrap();
            objects.add_primitive(Shape::Sphere(sphere), material(i), Transform::IDENTITY);
        }
        for i in 0..3 {
            let mesh = objects.add_mesh(scattered_triangles(&mut rng, 40, 8.0));
            objects.add_mesh_instance(mesh, material(i), Transform::IDENTITY);
        }
        for i in 0..45 {
            let centre = 8.0 * (rng.unit_vector() * rng.uniform());
            let moved = Transform::translate(centre).unwrap();
            let shape = match i % 4 {
                0 | 1 => Shape::Polygon(turned_square(&mut rng, centre)),
                2 => {
                    let (u, v) = (rng.unit_vector(), rng.unit_vector());
                    Shape::Parallelogram(Parallelogram::new(centre, u, v).unwrap())
                }
                _ => Shape::Disk(Disk::new(1.0, 0.3 * rng.uniform()).unwrap()),
            };
            // Disks moved, turned and stretched.
            let turned = Transform::rotate(rng.unit_vector(), 360.0 * rng.uniform()).unwrap();
            let stretched = Transform::scale(Vec3::new(1.5, 0.5, 1.0)).unwrap();
            let transform = if i % 4 == 3 {
                moved.then_after(&turned.then_after(&stretched))
            } else {
                Transform::IDENTITY
            };
            objects.add_primitive(shape, material(i), transform);
        }
        for i in 0..10 {
            let cylinder = Cylinder::new(0.5, 1.5, true).unwrap();
            let moved = Transform::translate(8.0 * rng.unit_vector() * rng.uniform()).unwrap();
            objects.add_primitive(Shape::Cylinder(cylinder), material(i), moved);
        }
        let floor = Plane::new(Vec3::new(0.0, -9.0, 0.0), Vec3::Y).unwrap();
        objects.add_primitive(Shape::Plane(floor), MaterialId(1), Transform::IDENTITY);
        let floor = PrimitiveId(objects.primitives.len() as u32 - 1);
        for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
            let world = World::build(&objects, kind);
            let opaque = world.opaque_entries(&[true, false, false]).unwrap();
            // Answered by crossings (of which: two or more, two materials,
            // a flat one, the floor), and left to the walk.
            let mut seen = [0; 6];
            for i in 0..4000 {
                let ray = shadow_ray(&mut rng, 10.0, if i % 2 == 0 { 20.0 } else { -20.0 });
                let ShadowPath::Crossed(passed) =
                    world.shadow_path(&ray, &opaque, &mut ShadowHint::default())
                else {
                    continue;
                };
                let Some(crossings) = world.shadow_crossings(&ray, &passed) else {
                    seen[5] += 1;
                    continue;
                };
                let (_, whole) = walk(&world, &ray, |r| world.intersect(r));
                let found = crossings
                    .iter()
                    .map(|c| (c.primitive, c.t))
                    .collect::<Vec<_>>();
                let walked = whole
                    .iter()
                    .map(|h| (h.primitive, h.t()))
                    .collect::<Vec<_>>();
                assert_eq!(found, walked, "{kind:?} {ray:?}");
                for c in crossings.iter() {
                    let hit = whole.iter().find(|h| h.primitive == c.primitive).unwrap();
                    assert_eq!(world.surface(&ray, hit).material, c.material);
                }
                let first = crossings.iter().next().map(|c| c.material);
                let flat = |c: &ShadowCrossing| match world.primitive_ref(c.primitive.0) {
                    PrimitiveRef::Shape(i) => objects.primitives[i as usize].shape.is_flat(),
                    _ => true,
                };
                seen[0] += 1;
                seen[1] += usize::from(found.len() >= 2);
                seen[2] += usize::from(crossings.iter().any(|c| Some(c.material) != first));
                seen[3] += usize::from(crossings.iter().any(flat));
                seen[4] += usize::from(crossings.iter().any(|c| c.primitive == floor));
            }
            assert!(seen.iter().all(|&n| n > 30), "{kind:?}: {seen:?}");
        }
    }

    #[test]
    fn crossings_of_two_spheres_at_the_same_place_are_left_to_the_walk() {
        let mut objects = Objects::default();
        for material in [1, 2, 1] {
            let sphere = Sphere::new(Vec3::ZERO, 1.0).unwrap();
            objects.add_primitive(
                Shape::Sphere(sphere),
                MaterialId(material),
                Transform::IDENTITY,
            );
        }
        let world = World::new(&objects);
        let ray = Ray::segment(Vec3::new(0.0, -3.0, 0.0), Vec3::Y, 6.0);
        // By primitive: the structure orders its entries as it likes.
        let listed = |primitives: &[u32]| {
            let mut passed = PassedEntries::EMPTY;
            for &p in primitives {
                let entry = world.entries.iter().position(|e| e.number == p).unwrap();
                passed.push(entry as u32, &world.entries);
            }
            world.shadow_crossings(&ray, &passed)
        };
        // Of one material or two: the walk crosses one of two surfaces in
        // the same place.
        assert_eq!(listed(&[0, 2]), None);
        assert_eq!(listed(&[0, 1]), None);
        let one = listed(&[1]).unwrap();
        assert_eq!(one.iter().map(|c| c.t).collect::<Vec<_>>(), [2.0, 4.0]);
        assert_eq!(listed(&[]).map(|c| c.iter().count()), Some(0));
    }

    #[test]
    fn a_crossing_at_the_end_of_the_ray_is_left_to_the_walk() {
        // A clear sphere, then a clear pane in the plane x = 3.
        let mut objects = Objects::default();
        let sphere = Sphere::new(Vec3::ZERO, 1.0).unwrap();
        objects.add_primitive(Shape::Sphere(sphere), MaterialId(1), Transform::IDENTITY);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let pane = Polygon::new(corners.map(|(y, z)| Vec3::new(3.0, y, z)).to_vec()).unwrap();
        objects.add_primitive(Shape::Polygon(pane), MaterialId(1), Transform::IDENTITY);
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[true, false]).unwrap();
        // From x = -5: the pane is 8 along.
        let crossings = |length: f64| {
            let ray = Ray::segment(Vec3::new(-5.0, 0.1, 0.2), Vec3::X, length);
            let path = world.shadow_path(&ray, &opaque, &mut ShadowHint::default());
            let ShadowPath::Crossed(passed) = path else {
                panic!("the ray crosses the sphere");
            };
            world.shadow_crossings(&ray, &passed)
        };
        let count = |length: f64| crossings(length).map(|c| c.iter().count());
        // Ending before the pane, past it, and just past it (a light in
        // the pane, as far as the walk's steps can tell).
        assert_eq!(count(7.5), Some(2));
        assert_eq!(count(8.001), Some(3));
        assert_eq!(count(8.0f64.next_up()), None);
    }

    #[test]
    fn more_crossings_than_the_list_holds_are_left_to_the_walk() {
        // Clear spheres in a row along x, two crossings each.
        let spheres = ShadowCrossings::CAPACITY / 2 + 1;
        let mut objects = Objects::default();
        for i in 0..spheres {
            let sphere = Sphere::new(Vec3::new(3.0 * i as f64, 0.0, 0.0), 1.0).unwrap();
            objects.add_primitive(Shape::Sphere(sphere), MaterialId(1), Transform::IDENTITY);
        }
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[true, false]).unwrap();
        let crossings = |end: f64| {
            let ray = Ray::segment(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, end + 5.0);
            let path = world.shadow_path(&ray, &opaque, &mut ShadowHint::default());
            let ShadowPath::Crossed(passed) = path else {
                panic!("the ray crosses spheres");
            };
            world.shadow_crossings(&ray, &passed)
        };
        // Past all but the last sphere: full; into the last: one too many.
        let last = 3.0 * (spheres - 1) as f64;
        let full = crossings(last - 1.5).expect("the list holds them");
        assert_eq!(full.iter().count(), ShadowCrossings::CAPACITY);
        let ts = full.iter().map(|c| c.t).collect::<Vec<_>>();
        assert!(ts.windows(2).all(|w| w[0] < w[1]), "{ts:?}");
        assert_eq!(crossings(last), None);
    }

    #[test]
    fn a_ray_past_more_entries_than_a_list_holds_walks_the_whole_structure() {
        let mut objects = Objects::default();
        for i in 0..PASSED_CAPACITY + 4 {
            let sphere = Sphere::new(Vec3::new(3.0 * i as f64, 0.0, 0.0), 1.0).unwrap();
            objects.add_primitive(Shape::Sphere(sphere), MaterialId(1), Transform::IDENTITY);
        }
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[true, false]).unwrap();
        let span = 3.0 * PASSED_CAPACITY as f64;
        let ray = |end: f64| Ray::segment(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, end + 5.0);
        let path = |ray: &Ray| world.shadow_path(ray, &opaque, &mut ShadowHint::default());
        let ShadowPath::Crossed(short) = path(&ray(span - 3.0)) else {
            panic!("the short ray crosses spheres");
        };
        assert!(short.is_listed());
        let long = ray(span + 12.0);
        let ShadowPath::Crossed(passed) = path(&long) else {
            panic!("the long ray crosses spheres");
        };
        assert_eq!(passed, PassedEntries::UNLISTED);
        let whole = walk(&world, &long, |r| world.intersect(r));
        assert_eq!(whole.1.len(), 2 * (PASSED_CAPACITY + 4));
        assert_eq!(
            walk(&world, &long, |r| world.intersect_passed(r, &passed)),
            whole
        );
    }

    #[test]
    fn with_every_material_clear_nothing_blocks() {
        let mut rng = Rng::new(12);
        let objects = mixed_scene(&mut rng);
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[false, false]).unwrap();
        let ray = Ray::segment(Vec3::new(0.0, -30.0, 0.0), Vec3::Y, 60.0);
        assert!(matches!(
            world.shadow_path(&ray, &opaque, &mut ShadowHint::default()),
            ShadowPath::Crossed(_)
        ));
        let all = world.opaque_entries(&[true, true]).unwrap();
        assert_eq!(
            world.shadow_path(&ray, &all, &mut ShadowHint::default()),
            ShadowPath::Blocked
        );
        let away = Ray::segment(Vec3::new(0.0, 40.0, 0.0), Vec3::Y, 10.0);
        assert_eq!(
            world.shadow_path(&away, &all, &mut ShadowHint::default()),
            ShadowPath::Clear
        );
    }

    #[test]
    fn two_entries_hit_at_the_same_parameter_are_told_apart_by_the_whole_walk() {
        // Two clear triangles over each other, as two primitives.
        let mut objects = Objects::default();
        let corners = [
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::Z,
        ];
        for _ in 0..2 {
            let triangle = crate::shape::Triangle::new(corners[0], corners[1], corners[2]).unwrap();
            objects.add_primitive(
                Shape::Triangle(triangle),
                MaterialId(1),
                Transform::IDENTITY,
            );
        }
        let world = World::new(&objects);
        let ray = Ray::segment(Vec3::new(0.1, -2.0, 0.0), Vec3::Y, 4.0);
        let whole = world.intersect(&ray).unwrap();
        // Both orders of the list: one of them is not the walk's.
        for order in [[0, 1], [1, 0]] {
            let mut passed = PassedEntries::EMPTY;
            for entry in order {
                passed.push(entry, &world.entries);
            }
            assert_eq!(world.intersect_passed(&ray, &passed), Some(whole));
        }
    }

    #[test]
    fn a_shape_found_by_a_search_leaves_the_entries_unlisted() {
        let mut objects = Objects::default();
        let torus = crate::shape::Torus::new(1.0, 0.3).unwrap();
        objects.add_primitive(Shape::Torus(torus), MaterialId(1), Transform::IDENTITY);
        let sphere = Sphere::new(Vec3::new(0.0, 3.0, 0.0), 0.5).unwrap();
        objects.add_primitive(Shape::Sphere(sphere), MaterialId(1), Transform::IDENTITY);
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[true, false]).unwrap();
        let path = |ray: &Ray| world.shadow_path(ray, &opaque, &mut ShadowHint::default());
        // Through the torus's tube (around the y axis) and through the
        // sphere alone.
        let tube = Ray::segment(Vec3::new(1.0, -5.0, 0.0), Vec3::Y, 10.0);
        let ShadowPath::Crossed(passed) = path(&tube) else {
            panic!("the ray crosses the torus");
        };
        assert!(!passed.is_listed());
        let sphere_only = Ray::segment(Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 10.0);
        let ShadowPath::Crossed(passed) = path(&sphere_only) else {
            panic!("the ray crosses the sphere");
        };
        assert!(passed.is_listed());
    }

    #[test]
    fn near_ties_span_a_billionth_and_at_least_one_step() {
        let (lower, upper) = near_tie(1.0);
        assert!(lower < 1.0 && 1.0 - lower <= 1.01e-9, "{lower}");
        assert!(upper > 1.0 && upper - 1.0 <= 1.01e-9, "{upper}");
        // Where the billionth rounds to nothing, one step up.
        let tiny = f64::from_bits(1);
        assert_eq!(near_tie(tiny), (tiny, tiny.next_up()));
        let bits = set_bits(1 | 1 << 5 | 1 << 31).collect::<Vec<_>>();
        assert_eq!(bits, [0, 5, 31]);
    }

    #[test]
    fn more_unbounded_entries_met_than_bits_leave_the_list_unknown() {
        // 34 clear planes across the ray's way: beyond the 32 bits.
        let mut objects = Objects::default();
        for i in 0..34 {
            let plane = Plane::new(Vec3::new(0.0, i as f64, 0.0), Vec3::Y).unwrap();
            objects.add_primitive(Shape::Plane(plane), MaterialId(1), Transform::IDENTITY);
        }
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[true, false]).unwrap();
        let path = |end: f64| {
            let ray = Ray::segment(Vec3::new(0.0, -0.5, 0.0), Vec3::Y, end);
            (
                ray,
                world.shadow_path(&ray, &opaque, &mut ShadowHint::default()),
            )
        };
        for (end, listed) in [(3.0, true), (40.0, false)] {
            let (ray, ShadowPath::Crossed(passed)) = path(end) else {
                panic!("the ray crosses planes");
            };
            assert_eq!(passed.is_listed(), listed, "{end}");
            let whole = walk(&world, &ray, |r| world.intersect(r));
            assert_eq!(
                walk(&world, &ray, |r| world.intersect_passed(r, &passed)),
                whole
            );
        }
    }
}
