//! Triangle meshes: vertices stored once and shared by the triangles that
//! use them, with optional per-vertex normals and texture coordinates
//! interpolated across each triangle.
//!
//! A mesh triangle is intersected exactly like [`crate::shape::Triangle`]
//! (the watertight test), so a mesh and the same triangles given one by one
//! render the same picture; only the memory differs. A zero-area triangle is
//! kept (its index stays what the file says) and is never hit.

use crate::math::prefetch::prefetch;
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};
use crate::shape::{LocalSurface, RayShear, ShapeHit, watertight};

/// Why a mesh could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} uses vertex {index}, but the mesh has {count} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex index it uses.
        index: u32,
        /// How many vertices there are.
        count: usize,
    },
    /// Normals or texture coordinates do not match the vertices one to one.
    #[error("the mesh has {count} {what} for {vertices} vertices")]
    AttributeCount {
        /// "normals" or "texture coordinates".
        what: &'static str,
        /// How many were given.
        count: usize,
        /// How many vertices there are.
        vertices: usize,
    },
    /// A coordinate that is NaN or infinite.
    #[error("vertex {index} has a {what} that is not a finite number")]
    NotFinite {
        /// "position", "normal" or "texture coordinate".
        what: &'static str,
        /// The vertex.
        index: usize,
    },
}

/// A triangle mesh with shared vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<DVec2>,
    triangles: Vec<[u32; 3]>,
}

/// A mesh triangle's surface: the geometric surface and the shading normal
/// interpolated from the vertex normals (the geometric normal when the mesh
/// has none).
///
/// The tangents `dpdu`, `dpdv` follow the texture coordinates: solved per
/// triangle from the differences of its corners' positions and (u, v). A
/// mesh without texture coordinates uses the barycentric ones, so the
/// tangents are the edges `p1 - p0` and `p2 - p0`; a triangle whose texture
/// coordinates span no area gets an arbitrary orthonormal pair around its
/// geometric normal (`dpdu × dpdv = normal`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSurface {
    /// Point, error bound, geometric normal, texture coordinates, tangent.
    pub local: LocalSurface,
    /// Unit shading normal.
    pub shading_normal: Vec3,
}

impl TriangleMesh {
    /// A mesh of `triangles` over `positions`; refused when a triangle names
    /// a missing vertex or a position is not finite.
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        if let Some(index) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NotFinite {
                what: "position",
                index,
            });
        }
        for (triangle, t) in triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    index,
                    count: positions.len(),
                });
            }
        }
        Ok(Self {
            positions,
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles,
        })
    }

    /// The mesh with one normal per vertex (any length; zero-length normals
    /// fall back to the geometric normal where used).
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Result<Self, MeshError> {
        self.check_count("normals", normals.len())?;
        if let Some(index) = normals.iter().position(|n| !n.is_finite()) {
            return Err(MeshError::NotFinite {
                what: "normal",
                index,
            });
        }
        self.normals = normals;
        Ok(self)
    }

    /// The mesh with one pair of texture coordinates per vertex.
    pub fn with_uvs(mut self, uvs: Vec<DVec2>) -> Result<Self, MeshError> {
        self.check_count("texture coordinates", uvs.len())?;
        if let Some(index) = uvs.iter().position(|uv| !uv.is_finite()) {
            return Err(MeshError::NotFinite {
                what: "texture coordinate",
                index,
            });
        }
        self.uvs = uvs;
        Ok(self)
    }

    fn check_count(&self, what: &'static str, count: usize) -> Result<(), MeshError> {
        if count == self.positions.len() {
            Ok(())
        } else {
            Err(MeshError::AttributeCount {
                what,
                count,
                vertices: self.positions.len(),
            })
        }
    }

    /// How many triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// The bytes its vertices and triangles take.
    pub fn heap_bytes(&self) -> u64 {
        (self.positions.len() * size_of::<Vec3>()
            + self.normals.len() * size_of::<Vec3>()
            + self.uvs.len() * size_of::<DVec2>()
            + self.triangles.len() * size_of::<[u32; 3]>()) as u64
    }

    /// True when it has no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The triangles, as vertex indices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The corners of triangle `i`.
    #[inline]
    pub fn corners(&self, i: u32) -> [Vec3; 3] {
        self.triangles[i as usize].map(|v| self.positions[v as usize])
    }

    /// The bounding box of triangle `i`.
    pub fn triangle_bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(self.corners(i))
    }

    /// Triangle `i` hit by `ray` (with its precomputed shear), closest in
    /// the ray's interval, barycentric `b1, b2` in `u, v`.
    #[inline]
    pub fn intersect(&self, i: u32, ray: &Ray, shear: &RayShear) -> Option<ShapeHit> {
        let [p0, p1, p2] = self.corners(i);
        watertight(p0, p1, p2, ray, shear)
    }

    /// Starts loading the corner indices of triangle `i`, the first read
    /// of [`TriangleMesh::surface`] (see [`TriangleMesh::prefetch_corners`]).
    #[inline]
    pub fn prefetch_indices(&self, i: u32) {
        if let Some(t) = self.triangles.get(i as usize) {
            prefetch(t);
        }
    }

    /// Starts loading what [`TriangleMesh::surface`] reads of triangle
    /// `i`'s corners: their positions and normals (not texture
    /// coordinates, which the meshes big enough to gain have not had).
    /// Reads the indices, so it pays after
    /// [`TriangleMesh::prefetch_indices`] has had time.
    #[inline]
    pub fn prefetch_corners(&self, i: u32) {
        let Some(t) = self.triangles.get(i as usize) else {
            return;
        };
        for &v in t {
            if let Some(p) = self.positions.get(v as usize) {
                prefetch(p);
            }
            if let Some(n) = self.normals.get(v as usize) {
                prefetch(n);
            }
        }
    }

    /// The surface of triangle `i` at a hit `ray` made, interpolating vertex
    /// normals and texture coordinates where the mesh has them.
    pub fn surface(&self, i: u32, ray: &Ray, hit: &ShapeHit) -> MeshSurface {
        let indices = self.triangles[i as usize].map(|v| v as usize);
        let [p0, p1, p2] = indices.map(|v| self.positions[v]);
        let (b1, b2) = (hit.u, hit.v);
        let b0 = 1.0 - b1 - b2;
        let (w0, w1, w2) = (b0 * p0, b1 * p1, b2 * p2);
        let (edge1, edge2) = (p1 - p0, p2 - p0);
        let normal = edge1
            .cross(edge2)
            .try_normalize()
            .unwrap_or_else(|| -ray.dir.normalize());
        let shading_normal = if self.normals.is_empty() {
            normal
        } else {
            let [n0, n1, n2] = indices.map(|v| self.normals[v]);
            (b0 * n0 + b1 * n1 + b2 * n2)
                .try_normalize()
                .unwrap_or(normal)
        };
        let (uv, (dpdu, dpdv)) = if self.uvs.is_empty() {
            (DVec2::new(b1, b2), (edge1, edge2))
        } else {
            let [t0, t1, t2] = indices.map(|v| self.uvs[v]);
            let tangents = uv_tangents([p0, p1, p2], [t0, t1, t2])
                .unwrap_or_else(|| normal.any_orthonormal_pair());
            (b0 * t0 + b1 * t1 + b2 * t2, tangents)
        };
        MeshSurface {
            local: LocalSurface {
                point: w0 + w1 + w2,
                point_error: gamma(7) * (w0.abs() + w1.abs() + w2.abs()),
                normal,
                uv,
                dpdu,
                dpdv,
            },
            shading_normal,
        }
    }
}

/// The derivatives `dpdu`, `dpdv` of the points of a triangle with corners
/// `p` and texture coordinates `uv` (the affine map from (u, v) to the
/// triangle's plane), or `None` when the texture coordinates span no area
/// relative to their size (collinear or repeated).
///
/// From `p_i - p_0 = (u_i - u_0) dpdu + (v_i - v_0) dpdv` for `i = 1, 2`.
fn uv_tangents(p: [Vec3; 3], uv: [DVec2; 3]) -> Option<(Vec3, Vec3)> {
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let det = d1.perp_dot(d2);
    if det.abs() <= 1e-12 * d1.length() * d2.length() {
        return None;
    }
    let dpdu = (d2.y * e1 - d1.y * e2) / det;
    let dpdv = (d1.x * e2 - d2.x * e1) / det;
    (dpdu.is_finite() && dpdv.is_finite()).then_some((dpdu, dpdv))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Triangle;

    fn quad() -> TriangleMesh {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).unwrap()
    }

    #[test]
    fn mesh_triangles_are_hit_exactly_like_single_triangles() {
        let mesh = quad();
        let single = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)).unwrap();
        let mut rng = crate::math::random::Rng::new(4);
        for _ in 0..500 {
            let origin = Vec3::new(rng.range(-0.5, 1.5), rng.range(-0.5, 1.5), 2.0);
            let ray = Ray::new(
                origin,
                Vec3::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), -1.0),
            );
            assert_eq!(
                mesh.intersect(0, &ray, &RayShear::new(&ray)),
                single.intersect(&ray)
            );
        }
    }

    #[test]
    fn vertex_normals_and_uvs_are_interpolated_with_the_barycentrics() {
        let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
        let mesh = quad()
            .with_normals(vec![Vec3::Z, tilted, tilted, Vec3::Z])
            .unwrap()
            .with_uvs(vec![
                DVec2::ZERO,
                DVec2::new(2.0, 0.0),
                DVec2::new(2.0, 2.0),
                DVec2::new(0.0, 2.0),
            ])
            .unwrap();
        let ray = Ray::new(Vec3::new(0.75, 0.25, 1.0), -Vec3::Z);
        let hit = mesh.intersect(0, &ray, &RayShear::new(&ray)).unwrap();
        let s = mesh.surface(0, &ray, &hit);
        assert!((s.local.point - Vec3::new(0.75, 0.25, 0.0)).length() < 1e-15);
        assert!((s.local.uv - DVec2::new(1.5, 0.5)).length() < 1e-12);
        assert_eq!(s.local.normal, Vec3::Z);
        let expected = (0.25 * Vec3::Z + 0.75 * tilted).normalize();
        assert!((s.shading_normal - expected).length() < 1e-12);
    }

    #[test]
    fn tangents_follow_the_texture_coordinates() {
        // u runs along +y and v along -x, at half speed.
        let mesh = quad()
            .with_uvs(vec![
                DVec2::ZERO,
                DVec2::new(0.0, -2.0),
                DVec2::new(2.0, -2.0),
                DVec2::new(2.0, 0.0),
            ])
            .unwrap();
        let ray = Ray::new(Vec3::new(0.75, 0.25, 1.0), -Vec3::Z);
        for triangle in [0, 1] {
            let Some(hit) = mesh.intersect(triangle, &ray, &RayShear::new(&ray)) else {
                continue;
            };
            let s = mesh.surface(triangle, &ray, &hit).local;
            assert!(
                (s.dpdu - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-15,
                "{}",
                s.dpdu
            );
            assert!(
                (s.dpdv - Vec3::new(-0.5, 0.0, 0.0)).length() < 1e-15,
                "{}",
                s.dpdv
            );
        }
        let bare = quad().surface(
            0,
            &ray,
            &quad().intersect(0, &ray, &RayShear::new(&ray)).unwrap(),
        );
        assert_eq!(
            (bare.local.dpdu, bare.local.dpdv),
            (Vec3::X, Vec3::new(1.0, 1.0, 0.0))
        );
    }

    #[test]
    fn solved_tangents_map_uv_differences_onto_the_edges() {
        let mut rng = crate::math::random::Rng::new(21);
        let mut solved = 0;
        for _ in 0..1000 {
            let p = [0; 3].map(|_| rng.point_in(Vec3::splat(-10.0), Vec3::splat(10.0)));
            let uv = [0; 3].map(|_| DVec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)));
            let Some((dpdu, dpdv)) = uv_tangents(p, uv) else {
                continue;
            };
            solved += 1;
            for i in [1, 2] {
                let d = uv[i] - uv[0];
                let rebuilt = d.x * dpdu + d.y * dpdv;
                let scale = p[i].length() + p[0].length();
                assert!((rebuilt - (p[i] - p[0])).length() < 1e-9 * scale);
            }
        }
        assert!(solved > 990);
    }

    #[test]
    fn degenerate_texture_coordinates_fall_back_to_a_frame_around_the_normal() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for uv in [
            [DVec2::ZERO; 3],
            [DVec2::ZERO, DVec2::new(1.0, 1.0), DVec2::new(2.0, 2.0)],
        ] {
            assert_eq!(uv_tangents(p, uv), None);
        }
        let mesh = TriangleMesh::new(p.to_vec(), vec![[0, 1, 2]])
            .unwrap()
            .with_uvs(vec![DVec2::ONE; 3])
            .unwrap();
        let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        let hit = mesh.intersect(0, &ray, &RayShear::new(&ray)).unwrap();
        let s = mesh.surface(0, &ray, &hit).local;
        assert!((s.dpdu.cross(s.dpdv) - Vec3::Z).length() < 1e-15);
        assert!((s.dpdu.length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn at_a_vertex_the_shading_normal_is_that_vertex_normal() {
        let n1 = Vec3::new(0.3, -0.2, 1.0).normalize();
        let mesh = quad()
            .with_normals(vec![Vec3::Z, n1, Vec3::Z, Vec3::Z])
            .unwrap();
        let hit = ShapeHit {
            t: 1.0,
            u: 1.0,
            v: 0.0,
            part: 0,
        };
        let ray = Ray::new(Vec3::new(1.0, 0.0, 1.0), -Vec3::Z);
        assert!((mesh.surface(0, &ray, &hit).shading_normal - n1).length() < 1e-15);
    }

    #[test]
    fn zero_area_triangles_are_kept_but_never_hit() {
        let positions = vec![Vec3::ZERO, Vec3::X, 2.0 * Vec3::X];
        let mesh = TriangleMesh::new(positions, vec![[0, 1, 2]]).unwrap();
        assert_eq!(mesh.len(), 1);
        for dir in [
            -Vec3::Z,
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, -1.0),
        ] {
            let ray = Ray::new(Vec3::new(0.5, 0.5, 0.5), dir);
            assert!(mesh.intersect(0, &ray, &RayShear::new(&ray)).is_none());
        }
    }

    #[test]
    fn bad_meshes_are_refused_with_the_culprit_named() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(
            TriangleMesh::new(positions.clone(), vec![[0, 1, 3]]),
            Err(MeshError::IndexOutOfRange {
                triangle: 0,
                index: 3,
                count: 3
            })
        );
        let err = TriangleMesh::new(positions.clone(), vec![[0, 1, 2]])
            .unwrap()
            .with_normals(vec![Vec3::Z])
            .unwrap_err();
        assert_eq!(err.to_string(), "the mesh has 1 normals for 3 vertices");
        let nan = vec![Vec3::ZERO, Vec3::new(f64::NAN, 0.0, 0.0), Vec3::Y];
        assert!(matches!(
            TriangleMesh::new(nan, vec![]),
            Err(MeshError::NotFinite { index: 1, .. })
        ));
    }

    #[test]
    fn prefetching_a_triangle_past_the_mesh_does_nothing() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let mesh = TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        for i in [0, 1, 2, u32::MAX] {
            mesh.prefetch_indices(i);
            mesh.prefetch_corners(i);
        }
    }
}
