//! A small triangle mesh held by the shape itself (`shape = "mesh"` with
//! its `vertices` and `triangles` written out), tested triangle by
//! triangle: for a few hundred triangles at most, above all as a CSG child
//! when closed. Big meshes belong in an OBJ or NFF file, whose triangles
//! share the scene's acceleration structure.
//!
//! **Closed.** A mesh is closed when every edge is shared by exactly two
//! triangles that run along it in opposite directions (consistently
//! oriented); [`SmallMesh::open_edge`] names the first edge that is not.
//! A closed mesh is a solid: its triangles are turned round when built if
//! they enclose a negative volume, so its normals point out, and the line
//! goes in where it meets a triangle facing it ([`SmallMesh::crossings`]:
//! every triangle along the whole line, in order).

use std::collections::HashMap;

use super::solid::{Crossing, Crossings};
use super::triangle::{RayShear, barycentric_surface, watertight};
use super::{LocalSurface, ShapeError, ShapeHit};
use crate::math::{Aabb, Ray, Vec3};

/// Where a mesh is not closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OpenEdge {
    /// The triangle, from 0, that has the edge.
    pub triangle: usize,
    /// The edge's first vertex, from 0, in the triangle's order.
    pub from: u32,
    /// The edge's second vertex.
    pub to: u32,
    /// What is wrong with it.
    pub why: &'static str,
}

impl std::fmt::Display for OpenEdge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the edge from vertex {} to vertex {} of triangle {} {}",
            self.from, self.to, self.triangle, self.why
        )
    }
}

#[derive(Clone, Debug, PartialEq)]
struct Data {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    bounds: Aabb,
    open: Option<OpenEdge>,
}

/// A triangle mesh tested by brute force.
#[derive(Clone, Debug, PartialEq)]
pub struct SmallMesh {
    data: Box<Data>,
}

impl SmallMesh {
    /// The mesh of `triangles` (indices into `positions`, from 0).
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, ShapeError> {
        if triangles.is_empty() {
            return Err(ShapeError::Degenerate {
                shape: "mesh",
                why: "it has no triangles",
            });
        }
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(ShapeError::NotFinite { what: "vertices" });
        }
        if triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= positions.len())
        {
            return Err(ShapeError::Degenerate {
                shape: "mesh",
                why: "a triangle names a vertex that does not exist",
            });
        }
        let bounds = Aabb::from_points(positions.iter().copied());
        let open = open_edge(&triangles);
        let mut data = Data {
            positions,
            triangles,
            bounds,
            open,
        };
        if open.is_none() && data.volume() < 0.0 {
            for t in &mut data.triangles {
                t.swap(1, 2);
            }
        }
        Ok(Self {
            data: Box::new(data),
        })
    }

    /// The first edge that is not shared by exactly two triangles running
    /// along it in opposite directions, or `None` for a closed mesh.
    pub fn open_edge(&self) -> Option<OpenEdge> {
        self.data.open
    }

    /// How many triangles the mesh has.
    pub fn len(&self) -> usize {
        self.data.triangles.len()
    }

    /// True when the mesh has no triangles (never: [`SmallMesh::new`]
    /// refuses that).
    pub fn is_empty(&self) -> bool {
        self.data.triangles.is_empty()
    }

    /// The vertices.
    pub fn positions(&self) -> &[Vec3] {
        &self.data.positions
    }

    /// The triangles, as indices into [`SmallMesh::positions`], turned
    /// to face out if the mesh is closed.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.data.triangles
    }

    fn corners(&self, i: usize) -> [Vec3; 3] {
        self.data.triangles[i].map(|v| self.data.positions[v as usize])
    }

    /// The closest hit in the ray's interval (`part` is the triangle).
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        self.data.bounds.intersect_ray(ray)?;
        let shear = RayShear::new(ray);
        let mut ray = *ray;
        let mut best = None;
        for i in 0..self.data.triangles.len() {
            let [a, b, c] = self.corners(i);
            if let Some(hit) = watertight(a, b, c, &ray, &shear) {
                ray.t_max = hit.t;
                best = Some(ShapeHit {
                    part: i as u32,
                    ..hit
                });
            }
        }
        best
    }

    /// True when the ray meets a triangle in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.data.bounds.intersect_ray(ray).is_none() {
            return false;
        }
        let shear = RayShear::new(ray);
        (0..self.data.triangles.len()).any(|i| {
            let [a, b, c] = self.corners(i);
            watertight(a, b, c, ray, &shear).is_some()
        })
    }

    /// The surface at a hit: the triangle's, (u, v) its barycentric
    /// coordinates.
    pub fn surface(&self, _ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        // A zero-area triangle is never hit, so its normal normalises.
        barycentric_surface(self.corners(hit.part as usize), hit.u, hit.v)
    }

    /// The bounding box of the vertices.
    pub fn bounds(&self) -> Aabb {
        self.data.bounds
    }

    /// True when `p` lies inside the (closed) mesh: the last crossing
    /// before `p` along a fixed line through it goes in.
    pub fn contains(&self, p: Vec3) -> bool {
        let b = &self.data.bounds;
        if !(p.cmpge(b.min).all() && p.cmple(b.max).all()) {
            return false;
        }
        // Off every axis and diagonal, so that it seldom meets an edge.
        let line = Ray::new(p, Vec3::new(0.5773, 0.5851, 0.5697));
        let mut crossings = Crossings::new();
        self.crossings(&line, &mut crossings);
        crossings
            .iter()
            .take_while(|c| c.hit.t < 0.0)
            .last()
            .is_some_and(|c| c.entering)
    }

    /// Appends every crossing of the (closed) mesh along the ray's whole
    /// line, in order: every triangle the line meets, going in where the
    /// triangle faces the line. Two crossings in the same direction in a
    /// row (the line through an edge meets both its triangles) are one.
    pub fn crossings(&self, ray: &Ray, out: &mut Crossings) {
        let mut line = *ray;
        line.t_min = f64::NEG_INFINITY;
        line.t_max = f64::INFINITY;
        let Some((near, far)) = self.data.bounds.intersect_ray(&line) else {
            return;
        };
        // The watertight test wants the mesh ahead of the origin: start
        // the line well before the box.
        let speed = ray.dir.length();
        let start = near - (far - near) - self.data.bounds.extent().length() / speed;
        let shifted = Ray::new(ray.at(start), ray.dir);
        let shear = RayShear::new(&shifted);
        let first = out.len();
        for i in 0..self.data.triangles.len() {
            let [a, b, c] = self.corners(i);
            if let Some(hit) = watertight(a, b, c, &shifted, &shear) {
                let along = (b - a).cross(c - a).dot(ray.dir);
                if along != 0.0 {
                    out.push(Crossing {
                        hit: ShapeHit {
                            t: start + hit.t,
                            part: i as u32,
                            ..hit
                        },
                        entering: along < 0.0,
                    });
                }
            }
        }
        out[first..].sort_by(|x, y| x.hit.t.total_cmp(&y.hit.t));
        let mut inside = false;
        let mut kept = first;
        for k in first..out.len() {
            if out[k].entering != inside {
                inside = out[k].entering;
                out[kept] = out[k];
                kept += 1;
            }
        }
        if inside {
            kept -= 1;
        }
        out.truncate(kept);
    }
}

impl Data {
    /// Six times the signed volume enclosed.
    fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.positions[v as usize]);
                a.dot(b.cross(c))
            })
            .sum()
    }
}

/// The first edge, in the order of the triangles, that is used twice in
/// the same direction or never in the other.
fn open_edge(triangles: &[[u32; 3]]) -> Option<OpenEdge> {
    let edges = |t: &[u32; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    let mut directed: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for (from, to) in edges(t) {
            if from == to {
                return Some(OpenEdge {
                    triangle: i,
                    from,
                    to,
                    why: "joins a vertex to itself",
                });
            }
            if directed.insert((from, to), i).is_some() {
                return Some(OpenEdge {
                    triangle: i,
                    from,
                    to,
                    why: "runs the same way in another triangle: the triangles \
                          around it are not consistently oriented, or more than \
                          two share it",
                });
            }
        }
    }
    for (i, t) in triangles.iter().enumerate() {
        for (from, to) in edges(t) {
            if !directed.contains_key(&(to, from)) {
                return Some(OpenEdge {
                    triangle: i,
                    from,
                    to,
                    why: "belongs to no other triangle: the mesh is open there",
                });
            }
        }
    }
    None
}

#[cfg(test)]
pub(crate) mod tests;
