//! A bicubic Bézier patch, intersected directly (no tessellation).
//!
//! Scene syntax: `shape = "bezier_patch"`, `points = [[p00, p01, p02, p03],
//! [p10, ...], [p20, ...], [p30, ...]]`: 16 control points `[x, y, z]` in 4
//! rows of 4, row i along u, point j of a row along v. A whole file of
//! patches is read with `shape = "patches"`, `file = "teapot.bpt"` (see
//! `docs/bpt.md`).
//!
//! The surface is `P(u, v) = Σ Bᵢ(u) Bⱼ(v) pᵢⱼ` over (u, v) in [0, 1]²,
//! with the cubic Bernstein polynomials `Bᵢ`. Texture coordinates are
//! (u, v); `dpdu` and `dpdv` are ∂P/∂u and ∂P/∂v (made perpendicular to the
//! normal where the normal is a limit, below). The normal is
//! `∂P/∂u × ∂P/∂v` normalised: "outward" is the side it points to, fixed
//! by the order of the points. A patch is open and two-sided; as glass it
//! needs neighbours that close a solid, oriented alike.
//!
//! # Intersection: Newton's method seeded by a subdivision hierarchy
//!
//! At construction the patch is split 4 ways in (u, v) to a depth of 2 to 5
//! (deeper where it is curved: [`hierarchy`]), each piece bounded by the
//! box of its own control points; each leaf keeps its piece's control net.
//! A ray walks that tree front to back, skipping boxes beyond the closest
//! hit so far. At each leaf it meets, the leaf's net is seen from the ray
//! (Kajiya's two planes: [`newton`]); if the box of the net's two plane
//! distances does not hold the origin, the ray misses the piece (convex
//! hull) and the leaf is done. Otherwise Newton's method on the two plane
//! distances (a 2×2 system in the piece's (s, t)) starts where the ray
//! meets the bilinear surface through the piece's corners, and a root on
//! the patch with `t` in the ray's interval, polished by one more step on
//! the patch's own net, becomes the new closest hit (the Benthin, Wald and
//! Slusallek scheme).
//!
//! A file of patches (`shape = "patches"`, `whitted render FILE.bpt`) puts
//! each leaf in the scene's acceleration structure as a shape of its own
//! ([`BezierPatch::pieces`]), so the scene's BVH does the walking, faster
//! than each patch's own hierarchy (measured: docs/performance-log.md,
//! "Bézier patches against their tessellation").
//!
//! Chosen over Bézier clipping because the work per ray is small and
//! bounded (at most 16 iterations per leaf met, no allocation), the
//! hierarchy is built once, and the same code answers closest and any hit.
//!
//! Failure modes: Newton's method converges slowly or not at all where the
//! Jacobian is singular, which for a ray is at the silhouette, so a ray
//! grazing the patch within about 1e-10 of its scale may be missed or hit
//! slightly off; a leaf met twice by one ray (possible only when grazing,
//! as leaves are flat to 2% of their size) yields one of its two roots,
//! not necessarily the nearer (they are close together then). A root is
//! accepted when the ray passes within 1e-10 of the patch's scale (its size
//! plus its distance from the ray's origin) of P(u, v).
//!
//! # Degenerate patches
//!
//! Where `∂P/∂u × ∂P/∂v` vanishes (a row of control points collapsed to
//! one point, as at the centre of the teapot's lid and bottom, or two
//! parallel derivatives at a corner), the normal is the limit taken a tiny
//! step towards the patch's centre (1e-7 in u and v, then larger steps if
//! that is still degenerate), and failing all, the normal of the control
//! net's diagonals. Constructors refuse non-finite or out-of-range points,
//! a patch whose points are all equal, or all collinear (no area).

mod bernstein;
mod hierarchy;
mod newton;

use self::bernstein::{ControlNet, evaluate};
use self::hierarchy::{Hierarchy, MAX_DEPTH};
use self::newton::RayFrame;
use super::{LocalSurface, ShapeError, ShapeHit, finite, not_tiny};
use crate::limits::{Held, MemoryBudget};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, magnitude, unit};
use std::sync::Arc;

/// Entries of the traversal stack: each level pushes at most four children
/// and pops one.
const STACK: usize = 3 * MAX_DEPTH as usize + 5;

/// The cross product of the derivatives counts as vanishing below this
/// fraction of the patch's size squared.
const VANISHING_NORMAL: f64 = 1e-11;

/// The steps towards the centre tried, in order, where the normal vanishes.
const LIMIT_STEPS: [f64; 3] = [1e-7, 1e-5, 1e-3];

/// Control points are collinear when the area they span is below this
/// fraction of their extent squared.
const COLLINEAR: f64 = 1e-12;

/// A bicubic Bézier patch, or one piece of it: a leaf of its hierarchy
/// ([`BezierPatch::pieces`]).
#[derive(Clone, Debug, PartialEq)]
pub struct BezierPatch {
    data: Arc<PatchData>,
    /// The hierarchy's node the shape is: 0 for the whole patch, a leaf
    /// for a piece.
    root: u32,
}

#[derive(Clone, Debug, PartialEq)]
struct PatchData {
    net: ControlNet,
    bounds: Aabb,
    /// The patch's size: the diagonal of its bounds.
    size: f64,
    /// Per axis, the largest magnitude of a control point (for the error
    /// bound of an evaluated point).
    magnitude: Vec3,
    /// The normal used where no limit of the derivatives gives one.
    fallback_normal: Vec3,
    hierarchy: Hierarchy,
    /// What it is charged in the memory ledger.
    held: Held,
}

impl BezierPatch {
    /// The patch with control points `points[i][j]`, i along u; refused
    /// when a point is not finite or out of range, when the points are
    /// all equal or all on one line, or when its hierarchy does not fit in
    /// the memory budget (it is charged to the ledger while the patch and
    /// its pieces live).
    pub fn new(points: [[Vec3; 4]; 4]) -> Result<Self, ShapeError> {
        for &p in points.iter().flatten() {
            finite("points", p)?;
        }
        let degenerate = |why| ShapeError::Degenerate {
            shape: "Bézier patch",
            why,
        };
        let bounds = Aabb::from_points(points.iter().flatten().copied());
        let size = magnitude::norm(bounds.extent());
        if size == 0.0 {
            return Err(degenerate("all its control points are equal"));
        }
        not_tiny("the patch's size", [size])?;
        let origin = points[0][0];
        let far = points
            .iter()
            .flatten()
            .map(|&p| p - origin)
            .max_by(|a, b| a.length().total_cmp(&b.length()))
            .unwrap_or(Vec3::ZERO);
        let unit_far = far / magnitude::norm(far).max(f64::MIN_POSITIVE);
        let spread = points
            .iter()
            .flatten()
            .map(|&p| magnitude::norm((p - origin).cross(unit_far)))
            .fold(0.0, f64::max);
        if spread <= COLLINEAR * size {
            return Err(degenerate(
                "its control points are collinear: it has no area",
            ));
        }
        let magnitude = points
            .iter()
            .flatten()
            .fold(Vec3::ZERO, |m, p| m.max(p.abs()));
        let diagonals = (points[3][3] - points[0][0]).cross(points[0][3] - points[3][0]);
        let fallback_normal = unit(diagonals).unwrap_or(Vec3::Z);
        let margin = 1e-9 * size + gamma(16) * magnitude.max_element();
        let hierarchy = Hierarchy::build(&points, margin);
        let bytes = size_of::<PatchData>()
            + hierarchy.nodes.capacity() * size_of::<hierarchy::Node>()
            + hierarchy.nets.capacity() * size_of::<ControlNet>();
        let charge = MemoryBudget::current().charge(
            "a Bézier patch's hierarchy",
            bytes as u64,
            "use fewer or flatter patches",
        )?;
        let mut held = Held::default();
        held.keep(charge);
        Ok(Self {
            root: 0,
            data: Arc::new(PatchData {
                net: points,
                bounds,
                size,
                magnitude,
                fallback_normal,
                hierarchy,
                held,
            }),
        })
    }

    /// The leaves of the patch's hierarchy, each a shape of its own with
    /// the leaf's box as bounds, reporting hits and surfaces in the whole
    /// patch's (u, v); together they are the patch. Many pieces of many
    /// patches under the scene's acceleration structure are walked faster
    /// than one hierarchy per patch (docs/performance-log.md, "Bézier patches
    /// against their tessellation").
    pub fn pieces(&self) -> impl Iterator<Item = BezierPatch> + '_ {
        let nodes = &self.data.hierarchy.nodes;
        let first = self.root as usize;
        nodes
            .iter()
            .enumerate()
            .skip(first)
            .filter(move |&(index, node)| node.is_leaf() && self.holds(index))
            .map(|(index, _)| Self {
                data: Arc::clone(&self.data),
                root: index as u32,
            })
    }

    /// True when node `index` is in the subtree of the shape's root.
    fn holds(&self, index: usize) -> bool {
        let nodes = &self.data.hierarchy.nodes;
        let (root, node) = (&nodes[self.root as usize], &nodes[index]);
        (0..2).all(|k| root.low[k] <= node.low[k] && node.high[k] <= root.high[k])
    }

    /// The control points, `[i][j]` with i along u.
    pub fn points(&self) -> &[[Vec3; 4]; 4] {
        &self.data.net
    }

    /// The closest hit in the ray's interval; `u` and `v` of the hit are
    /// the patch parameters.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        self.search(ray, false)
    }

    /// True when the ray meets the patch in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.search(ray, true).is_some()
    }

    /// Walks the hierarchy front to back; with `any`, stops at the first
    /// hit.
    fn search(&self, ray: &Ray, any: bool) -> Option<ShapeHit> {
        let nodes = &self.data.hierarchy.nodes;
        let nets = &self.data.hierarchy.nets;
        let (entry, _) = nodes[self.root as usize].bounds.intersect_ray(ray)?;
        let mut best: Option<ShapeHit> = None;
        let mut t_max = ray.t_max;
        let mut stack = [(0u32, 0.0f64); STACK];
        stack[0] = (self.root, entry);
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (index, entry) = stack[len];
            if entry >= t_max {
                continue;
            }
            let node = &nodes[index as usize];
            if node.is_leaf() {
                let frame = RayFrame::new(&nets[node.net as usize], ray)?;
                if !frame.faces() {
                    continue;
                }
                if let Some(root) = frame.solve(node, &self.data.net, ray.t_min, t_max) {
                    t_max = root.t;
                    best = Some(ShapeHit {
                        t: root.t,
                        u: root.u,
                        v: root.v,
                        part: 0,
                    });
                    if any {
                        return best;
                    }
                }
                continue;
            }
            let clipped = Ray { t_max, ..*ray };
            let mut children = [(0u32, f64::INFINITY); 4];
            for (k, child) in children.iter_mut().enumerate() {
                let index = node.children + k as u32;
                if let Some((near, _)) = nodes[index as usize].bounds.intersect_ray(&clipped) {
                    *child = (index, near);
                }
            }
            // Farthest pushed first, so the nearest is taken next.
            children.sort_by(|a, b| b.1.total_cmp(&a.1));
            for child in children.into_iter().filter(|c| c.1.is_finite()) {
                stack[len] = child;
                len += 1;
            }
        }
        best
    }

    /// The surface at a hit: P(u, v), its derivatives and the normal.
    pub fn surface(&self, _ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let d = &self.data;
        let (u, v) = (hit.u.clamp(0.0, 1.0), hit.v.clamp(0.0, 1.0));
        let e = evaluate(&d.net, u, v);
        let normal = self.normal_at(u, v);
        let flatten = |tangent: Vec3| tangent - normal * normal.dot(tangent);
        LocalSurface {
            point: e.point,
            point_error: gamma(24) * d.magnitude,
            normal,
            uv: DVec2::new(u, v),
            dpdu: flatten(e.du),
            dpdv: flatten(e.dv),
        }
    }

    /// The unit normal at (u, v): `∂P/∂u × ∂P/∂v`, or where that vanishes
    /// its limit a small step towards the centre of the patch.
    fn normal_at(&self, u: f64, v: f64) -> Vec3 {
        let d = &self.data;
        let floor = VANISHING_NORMAL * d.size * d.size;
        let at = |u: f64, v: f64| {
            let e = evaluate(&d.net, u, v);
            let n = e.du.cross(e.dv);
            (magnitude::norm(n) > floor).then(|| unit(n)).flatten()
        };
        at(u, v)
            .or_else(|| {
                LIMIT_STEPS.iter().find_map(|&step| {
                    let inward = |x: f64| x + step * (0.5 - x).signum();
                    at(inward(u), inward(v))
                })
            })
            .unwrap_or(d.fallback_normal)
    }

    /// The bounding box of the control points (which contains the patch),
    /// or of a piece's.
    pub fn bounds(&self) -> Aabb {
        if self.root == 0 {
            self.data.bounds
        } else {
            self.data.hierarchy.nodes[self.root as usize].bounds
        }
    }
}

#[cfg(test)]
mod tests;
