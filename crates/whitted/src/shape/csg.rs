//! Constructive solid geometry: the union, intersection or difference
//! (the first child minus all the others) of closed solids, each child
//! with its own transform and, optionally, its own material.
//!
//! **Ray classification** (Roth 1982). Every leaf solid lists where the
//! ray's line crosses it, going in or out ([`Shape::crossings`]); each
//! operation sweeps its children's lists in order of `t`, keeping whether
//! the line is inside each child, and records where its own answer
//! changes. The hit is the first change of the whole tree's answer in the
//! ray's interval, reported as the leaf's own hit, so the leaf computes
//! the surface. Nested CSG children are flattened into one tree of leaves
//! when built, their transforms composed.
//!
//! **Coincident surfaces.** Where two children's surfaces coincide (a
//! cutter sharing a face with the base, two boxes stacked face to face),
//! rounding puts their crossings a hair apart in either order, which
//! would leave a sliver of solid (or of space) and speckles. The rule:
//! crossings of different children closer than [`COINCIDENT`] times the
//! CSG's size are one place, taken at once, so no sliver arises (the cut
//! face is cut away, the stacked boxes are one solid, a box minus itself
//! is nothing); where the answer changes there, the surface is the first
//! child's (in the order written) among those crossing the same way. A
//! stretch of solid or of space shorter than that is dropped as well.
//!
//! **Normals and materials.** A surface that comes from a subtracted child
//! (an odd number of times, through nested differences) has its normal
//! turned round, so every normal points out of the result and a ray
//! entering the result meets a normal against it: refraction and the
//! medium stack see a CSG object as any other closed solid. A leaf's
//! material is its own, else that of the nearest CSG child above it that
//! has one, else the CSG object's ([`Csg::material`] answers `None`).
//!
//! **One medium.** The medium stack of refraction is keyed by the solid's
//! medium, not by the material of the surface crossed, so a ray entering
//! through one child's surface and leaving through another's (of another
//! material) leaves the solid. The medium is the CSG object's own
//! material; the scene reader fills an object that has none with its
//! first solid's ([`Csg::filled_with`]). The children's materials give
//! their surfaces' colour, mirror and transparency; their indices of
//! refraction are not used.

use smallvec::SmallVec;

use super::solid::{Crossing, Crossings, Solidity};
use super::{LocalSurface, Shape, ShapeHit};
use crate::math::{Aabb, Ray, Transform, Vec3};

/// Crossings of different children closer than this fraction of the
/// CSG's size (the diagonal of its bounds) are taken as one surface.
pub const COINCIDENT: f64 = 1e-9;

/// The most leaves one CSG object holds: a hit keeps the leaf in the high
/// half of [`ShapeHit::part`].
pub const MAX_LEAVES: usize = 1 << 16;

/// How a CSG object combines its children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOperation {
    /// Inside any child.
    Union,
    /// Inside every child.
    Intersection,
    /// Inside the first child and none of the others.
    Difference,
}

impl CsgOperation {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Union => "union",
            Self::Intersection => "intersection",
            Self::Difference => "difference",
        }
    }

    /// The operation's answer for children insides `inside`.
    fn combine(self, inside: &[bool]) -> bool {
        match self {
            Self::Union => inside.iter().any(|&i| i),
            Self::Intersection => inside.iter().all(|&i| i),
            Self::Difference => inside[0] && !inside[1..].iter().any(|&i| i),
        }
    }
}

/// One child as given to [`Csg::new`].
#[derive(Clone, Debug, PartialEq)]
pub struct CsgChild {
    /// A closed solid, in the child's own space (possibly a CSG object).
    pub shape: Shape,
    /// Child space to the CSG's space; `None` means they coincide.
    pub transform: Option<Transform>,
    /// The child's material (an index the world reads as its material
    /// id); `None` takes the parent's.
    pub material: Option<u32>,
}

/// Why a CSG object could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CsgError {
    /// Fewer children than the operation needs.
    #[error("a {} needs at least two children, got {count}", operation.name())]
    TooFewChildren {
        /// The operation.
        operation: CsgOperation,
        /// How many children were given.
        count: usize,
    },
    /// A child is not a closed solid.
    #[error("child {index} ({kind}) is not a closed solid: {why}")]
    Open {
        /// Which child, from 0.
        index: usize,
        /// Its shape's name.
        kind: &'static str,
        /// Why it is open.
        why: &'static str,
    },
    /// A mesh child with more triangles than a hit can name.
    #[error("child {index} is a mesh of {count} triangles; a CSG child has at most {MAX_LEAVES}")]
    TooManyTriangles {
        /// Which child, from 0.
        index: usize,
        /// How many triangles it has.
        count: usize,
    },
    /// More leaves than [`MAX_LEAVES`].
    #[error("a CSG object holds at most {MAX_LEAVES} solids, this one has {count}")]
    TooManyLeaves {
        /// How many leaves there are.
        count: usize,
    },
}

/// A solid of the tree, in its own space.
#[derive(Clone, Debug, PartialEq)]
struct Leaf {
    shape: Shape,
    /// Leaf space to the CSG's space.
    transform: Option<Transform>,
    material: Option<u32>,
    /// True when the leaf is subtracted an odd number of times: its
    /// normals are turned round.
    complemented: bool,
    /// Its bounds in the CSG's space, a little widened: a line that
    /// misses them does not cross the leaf.
    bounds: Aabb,
}

/// A node's child: a leaf or another node, by index.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Part {
    Leaf(u32),
    Node(u32),
}

/// An operation over parts.
#[derive(Clone, Debug, PartialEq)]
struct Node {
    operation: CsgOperation,
    children: Vec<Part>,
}

#[derive(Clone, Debug, PartialEq)]
struct Data {
    leaves: Vec<Leaf>,
    /// The root is node 0.
    nodes: Vec<Node>,
    bounds: Aabb,
    /// The diagonal of `bounds`.
    size: f64,
    /// The material filling the solid, when not the object's own.
    medium: Option<u32>,
}

/// A CSG object.
#[derive(Clone, Debug, PartialEq)]
pub struct Csg {
    data: Box<Data>,
}

/// A place where a node's answer changes along the line.
#[derive(Clone, Copy, Debug)]
struct Boundary {
    /// The leaf whose surface it is.
    leaf: u32,
    /// The leaf's hit there.
    hit: ShapeHit,
    /// True when the line goes into the node's solid.
    entering: bool,
}

impl Csg {
    /// `operation` over `children`, each a closed solid.
    pub fn new(operation: CsgOperation, children: Vec<CsgChild>) -> Result<Self, CsgError> {
        if children.len() < 2 {
            return Err(CsgError::TooFewChildren {
                operation,
                count: children.len(),
            });
        }
        for (index, child) in children.iter().enumerate() {
            if let Shape::Mesh(mesh) = &child.shape
                && mesh.len() > MAX_LEAVES
            {
                return Err(CsgError::TooManyTriangles {
                    index,
                    count: mesh.len(),
                });
            }
            if let Solidity::Open(why) = child.shape.solidity() {
                return Err(CsgError::Open {
                    index,
                    kind: child.shape.kind(),
                    why,
                });
            }
        }
        let mut data = Data {
            leaves: Vec::new(),
            nodes: vec![Node {
                operation,
                children: Vec::new(),
            }],
            bounds: Aabb::EMPTY,
            size: 0.0,
            medium: None,
        };
        let mut parts = Vec::with_capacity(children.len());
        let mut child_bounds = Vec::with_capacity(children.len());
        for (index, child) in children.into_iter().enumerate() {
            let subtracted = operation == CsgOperation::Difference && index > 0;
            let local = child.shape.bounds();
            child_bounds.push(child.transform.map_or(local, |t| t.bounds_to_world(&local)));
            parts.push(data.adopt(child, subtracted));
        }
        data.nodes[0].children = parts;
        for leaf in &mut data.leaves {
            let local = leaf.shape.bounds();
            let b = leaf.transform.map_or(local, |t| t.bounds_to_world(&local));
            leaf.bounds = b.expanded(1e-9 * b.extent().length());
        }
        if data.leaves.len() > MAX_LEAVES {
            return Err(CsgError::TooManyLeaves {
                count: data.leaves.len(),
            });
        }
        data.bounds = match operation {
            CsgOperation::Union => child_bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(b)),
            CsgOperation::Intersection => child_bounds[1..]
                .iter()
                .try_fold(child_bounds[0], |a, b| a.intersection(b))
                .unwrap_or(Aabb::EMPTY),
            CsgOperation::Difference => child_bounds[0],
        };
        data.size = if data.bounds.is_empty() {
            0.0
        } else {
            data.bounds.extent().length()
        };
        Ok(Self {
            data: Box::new(data),
        })
    }

    /// The operation at the top of the tree.
    pub fn operation(&self) -> CsgOperation {
        self.data.nodes[0].operation
    }

    /// How many solids the tree holds, nested CSG flattened.
    pub fn leaf_count(&self) -> usize {
        self.data.leaves.len()
    }

    /// The object-space bounds.
    pub fn bounds(&self) -> Aabb {
        self.data.bounds
    }

    /// The material of the leaf a hit is on, if the leaf (or a CSG child
    /// above it) has one of its own.
    pub fn material(&self, hit: &ShapeHit) -> Option<u32> {
        self.data.leaves[(hit.part >> 16) as usize].material
    }

    /// The material whose index of refraction fills the solid, when it is
    /// not the object's own (set by [`Csg::filled_with`]). A CSG object is
    /// one medium: a ray that enters through one child's surface and
    /// leaves through another's is inside the same medium between them.
    pub fn medium(&self) -> Option<u32> {
        self.data.medium
    }

    /// The object filled with `material` (`None`: with the object's own).
    #[must_use]
    pub fn filled_with(mut self, material: Option<u32>) -> Self {
        self.data.medium = material;
        self
    }

    /// The first solid's own material (depth-first, inherited from a CSG
    /// child above it), if it has one.
    pub fn first_material(&self) -> Option<u32> {
        self.data.leaves[0].material
    }

    /// True when `p` lies inside the solid.
    pub fn contains(&self, p: Vec3) -> bool {
        self.data.contains(Part::Node(0), p)
    }

    /// The closest place in the ray's interval where it enters or leaves
    /// the solid.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        self.data.classify(ray, |boundaries| {
            boundaries
                .iter()
                .find(|b| ray.contains(b.hit.t))
                .map(|b| ShapeHit {
                    part: b.leaf << 16 | b.hit.part,
                    ..b.hit
                })
        })
    }

    /// True when the ray enters or leaves the solid in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// Every crossing of the solid's surface along the ray's whole line.
    pub fn crossings(&self, ray: &Ray, out: &mut Crossings) {
        self.data.classify(ray, |boundaries| {
            out.extend(boundaries.iter().map(|b| Crossing {
                hit: ShapeHit {
                    part: b.leaf << 16 | b.hit.part,
                    ..b.hit
                },
                entering: b.entering,
            }));
        });
    }

    /// The surface at a hit: the leaf's, in the CSG's space, its normal
    /// turned round where the leaf is subtracted.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let leaf = &self.data.leaves[(hit.part >> 16) as usize];
        let leaf_hit = ShapeHit {
            part: hit.part & 0xffff,
            ..*hit
        };
        let mut s = match &leaf.transform {
            None => leaf.shape.surface(ray, &leaf_hit),
            Some(t) => {
                let local = leaf.shape.surface(&t.ray_to_object(ray), &leaf_hit);
                let (point, point_error) =
                    t.point_with_error_to_world(local.point, local.point_error);
                LocalSurface {
                    point,
                    point_error,
                    normal: t.normal_to_world(local.normal).normalize(),
                    uv: local.uv,
                    dpdu: t.vector_to_world(local.dpdu),
                    dpdv: t.vector_to_world(local.dpdv),
                }
            }
        };
        if leaf.complemented {
            s.normal = -s.normal;
        }
        s
    }
}

impl Data {
    /// Adds `child` (flattening a CSG child) and returns its part.
    fn adopt(&mut self, child: CsgChild, subtracted: bool) -> Part {
        let Shape::Csg(inner) = child.shape else {
            self.leaves.push(Leaf {
                shape: child.shape,
                transform: child.transform,
                material: child.material,
                complemented: subtracted,
                bounds: Aabb::EMPTY,
            });
            return Part::Leaf(self.leaves.len() as u32 - 1);
        };
        let inner = *inner.data;
        let (leaf_base, node_base) = (self.leaves.len() as u32, self.nodes.len() as u32);
        for leaf in inner.leaves {
            let transform = match (child.transform, leaf.transform) {
                (Some(outer), Some(own)) => Some(outer.then_after(&own)),
                (outer, own) => outer.or(own),
            };
            self.leaves.push(Leaf {
                transform,
                material: leaf.material.or(child.material),
                complemented: leaf.complemented != subtracted,
                ..leaf
            });
        }
        let shift = |part: Part| match part {
            Part::Leaf(i) => Part::Leaf(i + leaf_base),
            Part::Node(i) => Part::Node(i + node_base),
        };
        self.nodes.extend(inner.nodes.into_iter().map(|node| Node {
            children: node.children.into_iter().map(shift).collect(),
            ..node
        }));
        Part::Node(node_base)
    }

    fn contains(&self, part: Part, p: Vec3) -> bool {
        match part {
            Part::Leaf(i) => {
                let leaf = &self.leaves[i as usize];
                let local = leaf
                    .transform
                    .map_or(p, |t| t.object_from_world().transform_point3(p));
                leaf.shape.contains(local)
            }
            Part::Node(i) => {
                let node = &self.nodes[i as usize];
                let inside: Vec<bool> =
                    node.children.iter().map(|&c| self.contains(c, p)).collect();
                node.operation.combine(&inside)
            }
        }
    }

    /// Calls `f` with where the whole tree's answer changes along the
    /// ray's line, in order, alternately in and out. The lists are built
    /// in a buffer of the thread's, reused from ray to ray.
    fn classify<R>(&self, ray: &Ray, f: impl FnOnce(&[Boundary]) -> R) -> R {
        let speed = ray.dir.length();
        let tolerance = if speed > 0.0 {
            COINCIDENT * self.size / speed
        } else {
            0.0
        };
        let mut line = *ray;
        line.t_min = f64::NEG_INFINITY;
        line.t_max = f64::INFINITY;
        let run = |arena: &mut Vec<Boundary>| {
            arena.clear();
            let start = self.boundaries(Part::Node(0), &line, tolerance, arena);
            f(&arena[start..])
        };
        ARENA.with(|arena| match arena.try_borrow_mut() {
            Ok(mut arena) => run(&mut arena),
            // Only if `f` classified again: a buffer of its own.
            Err(_) => run(&mut Vec::new()),
        })
    }

    /// Appends the boundaries of `part` along `line` (the ray with an
    /// unbounded interval) to `arena` and returns where they start.
    fn boundaries(
        &self,
        part: Part,
        line: &Ray,
        tolerance: f64,
        arena: &mut Vec<Boundary>,
    ) -> usize {
        let start = arena.len();
        let node = match part {
            Part::Leaf(i) => {
                self.leaf_boundaries(i, line, arena);
                return start;
            }
            Part::Node(i) => &self.nodes[i as usize],
        };
        let mut lists: SmallVec<[(usize, usize); 8]> = SmallVec::new();
        for (k, &child) in node.children.iter().enumerate() {
            let first = self.boundaries(child, line, tolerance, arena);
            let needed = match node.operation {
                CsgOperation::Union => false,
                CsgOperation::Intersection => true,
                CsgOperation::Difference => k == 0,
            };
            if needed && first == arena.len() {
                arena.truncate(start);
                return start;
            }
            lists.push((first, arena.len()));
        }
        let mut crossed = lists.iter().filter(|(a, b)| a < b);
        let (one, two) = (crossed.next().copied(), crossed.next());
        if node.operation == CsgOperation::Union && two.is_none() {
            let (a, b) = one.unwrap_or((start, start));
            arena.copy_within(a..b, start);
            arena.truncate(start + b - a);
            return start;
        }
        let out = arena.len();
        sweep(node.operation, arena, &lists, tolerance);
        let end = out + tidy(&mut arena[out..], tolerance);
        arena.copy_within(out..end, start);
        arena.truncate(start + end - out);
        start
    }

    /// Appends the crossings of leaf `i` along `line` to `arena`.
    fn leaf_boundaries(&self, i: u32, line: &Ray, arena: &mut Vec<Boundary>) {
        let leaf = &self.leaves[i as usize];
        if leaf.bounds.intersect_ray(line).is_none() {
            return;
        }
        let mut crossings = Crossings::new();
        match &leaf.transform {
            None => leaf.shape.crossings(line, &mut crossings),
            Some(t) => leaf.shape.crossings(&t.ray_to_object(line), &mut crossings),
        }
        arena.extend(crossings.into_iter().map(|c| Boundary {
            leaf: i,
            hit: c.hit,
            entering: c.entering,
        }));
    }
}

thread_local! {
    /// The boundary lists of the ray being classified on this thread.
    static ARENA: std::cell::RefCell<Vec<Boundary>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Appends to `arena` where `operation`'s answer over the children's
/// boundary lists (`arena[a..b]` for each `(a, b)` of `lists`) changes.
/// The lists are walked together in order of `t`; crossings of different
/// children closer than `tolerance` to the first of them are taken at
/// once, as one place, and where the answer changes there the earliest
/// child whose crossing goes the same way gives the surface.
fn sweep(
    operation: CsgOperation,
    arena: &mut Vec<Boundary>,
    lists: &[(usize, usize)],
    tolerance: f64,
) {
    let mut next: SmallVec<[usize; 8]> = lists.iter().map(|&(a, _)| a).collect();
    let mut inside: SmallVec<[bool; 8]> = SmallVec::from_elem(false, lists.len());
    let mut answer = false;
    // The crossings taken at one place: (child, boundary).
    let mut group: SmallVec<[(usize, Boundary); 4]> = SmallVec::new();
    loop {
        let earliest = lists
            .iter()
            .enumerate()
            .filter(|&(k, &(_, end))| next[k] < end)
            .map(|(k, _)| arena[next[k]].hit.t)
            .fold(f64::INFINITY, f64::min);
        if earliest == f64::INFINITY {
            return;
        }
        group.clear();
        for (k, &(_, end)) in lists.iter().enumerate() {
            while next[k] < end
                && arena[next[k]].hit.t - earliest < tolerance.max(0.0) + f64::MIN_POSITIVE
            {
                let b = arena[next[k]];
                group.push((k, b));
                inside[k] = b.entering;
                next[k] += 1;
            }
        }
        let now = operation.combine(&inside);
        if now == answer {
            continue;
        }
        answer = now;
        let subtracted = |k: usize| operation == CsgOperation::Difference && k > 0;
        let (_, b) = group
            .iter()
            .find(|&&(k, b)| (b.entering != subtracted(k)) == now)
            .unwrap_or(&group[0]);
        arena.push(Boundary {
            entering: now,
            ..*b
        });
    }
}

/// Drops from `boundaries` (alternately in and out, starting in) the
/// stretches of solid or of space shorter than `tolerance`, in place;
/// returns how many are left.
fn tidy(boundaries: &mut [Boundary], tolerance: f64) -> usize {
    let mut kept = 0;
    for k in (0..boundaries.len() / 2).map(|k| 2 * k) {
        let (enter, leave) = (boundaries[k], boundaries[k + 1]);
        if leave.hit.t - enter.hit.t < tolerance {
            continue;
        }
        if kept > 0 && enter.hit.t - boundaries[kept - 1].hit.t < tolerance {
            boundaries[kept - 1] = leave;
        } else {
            boundaries[kept] = enter;
            boundaries[kept + 1] = leave;
            kept += 2;
        }
    }
    kept
}

#[cfg(test)]
mod tests;
