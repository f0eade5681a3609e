//! A planar polygon with any number of vertices, convex or concave.
//!
//! Scene syntax: `shape = "polygon"`,
//! `vertices = [[x0, y0, z0], [x1, y1, z1], [x2, y2, z2], ...]`
//! (at least three; the NFF `p` primitive maps to it directly).
//!
//! The front faces the viewer who sees the vertices counter-clockwise: the
//! normal is the one of Newell's method, which stays robust for concave
//! polygons and for nearly collinear runs of vertices. Inside is decided by
//! the even-odd rule, so a self-intersecting outline has holes where it
//! overlaps itself.
//!
//! Texture coordinates are planar and in world units: `(u, v)` are the
//! coordinates of `p - v0` along the unit direction of the first edge that is
//! not vanishingly short (its part in the plane) and along
//! `normal × that direction`; `dpdu` is that unit direction and `dpdv` the
//! second one.
//!
//! The vertices may stray from the plane by 1e-4 of the polygon's size plus
//! 3e-5 of its largest coordinate: enough for coordinates printed with six
//! significant digits, as the SPD writes them. The polygon is then hit and
//! reprojected as the plane through `v0` with the Newell normal (see
//! [`super::plane`]).

use super::outline::Outline;
use super::plane::{onto_plane, plane_hit};
use super::{LocalSurface, ShapeError, ShapeHit, finite, not_tiny};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, magnitude, unit};

/// Vertices count as collinear when twice the polygon's area is below this
/// fraction of `Σ |wᵢ| |wᵢ₊₁|` (`wᵢ = vᵢ - v0`): the normal would be
/// rounding noise.
const COLLINEAR: f64 = 1e-12;

/// Allowed distance of a vertex from the plane, relative to the polygon's
/// size (its bounding-box diagonal).
const PLANARITY_SIZE: f64 = 1e-4;

/// Allowed distance of a vertex from the plane, relative to the largest
/// coordinate (six printed digits round by up to 5e-6 of each coordinate).
const PLANARITY_COORDINATE: f64 = 3e-5;

/// Edges shorter than this fraction of the longest edge are not used for the
/// texture frame.
const SHORT_EDGE: f64 = 1e-6;

/// A planar polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    vertices: Box<[Vec3]>,
    normal: Vec3,
    tangent: Vec3,
    /// The vertices on two coordinate axes (the normal's dominant axis is
    /// dropped), for the inside test.
    outline: Box<Outline>,
}

impl Polygon {
    /// The polygon through `vertices`, in order; refused with fewer than
    /// three vertices, with no area, or when the vertices are not in one
    /// plane.
    pub fn new(vertices: Vec<Vec3>) -> Result<Self, ShapeError> {
        let degenerate = |why| ShapeError::Degenerate {
            shape: "polygon",
            why,
        };
        if vertices.len() < 3 {
            return Err(degenerate("it needs at least three vertices"));
        }
        let v0 = vertices[0];
        for &v in &vertices {
            finite("vertex", v)?;
        }

        not_tiny(
            "the polygon's size",
            vertices.iter().map(|&v| magnitude::norm(v - v0)),
        )?;

        // Newell's normal, from vertices relative to v0 so that polygons far
        // from the origin lose no precision. Its terms are each parallel to
        // the plane's normal; in an outline that crosses itself (a bow tie)
        // they may cancel, and then the terms turned to agree with the
        // largest one give the plane instead.
        let terms: Vec<Vec3> = vertices
            .windows(2)
            .map(|pair| (pair[0] - v0).cross(pair[1] - v0))
            .collect();
        let scale: f64 = vertices
            .windows(2)
            .map(|pair| (pair[0] - v0).length() * (pair[1] - v0).length())
            .sum();
        let has_area = |sum: Vec3| unit(sum).filter(|_| sum.length() > COLLINEAR * scale);
        let newell: Vec3 = terms.iter().sum();
        let largest = terms
            .iter()
            .copied()
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))
            .unwrap_or(Vec3::ZERO);
        let aligned: Vec3 = terms
            .iter()
            .map(|&t| if t.dot(largest) < 0.0 { -t } else { t })
            .sum();
        let normal = has_area(newell)
            .or_else(|| has_area(aligned))
            .ok_or(degenerate("its vertices are collinear"))?;

        let bounds = Aabb::from_points(vertices.iter().copied());
        let largest = bounds.min.abs().max(bounds.max.abs()).max_element();
        let tolerance = PLANARITY_SIZE * bounds.extent().length() + PLANARITY_COORDINATE * largest;
        for (vertex, &v) in vertices.iter().enumerate() {
            let deviation = normal.dot(v - v0).abs();
            if deviation > tolerance {
                return Err(ShapeError::NotPlanar {
                    vertex,
                    deviation,
                    tolerance,
                });
            }
        }

        let in_plane = |i: usize| {
            let edge = vertices[(i + 1) % vertices.len()] - vertices[i];
            edge - normal.dot(edge) * normal
        };
        let longest = (0..vertices.len())
            .map(|i| in_plane(i).length())
            .fold(0.0, f64::max);
        let tangent = (0..vertices.len())
            .map(in_plane)
            .filter(|edge| edge.length() >= SHORT_EDGE * longest)
            .find_map(unit)
            .ok_or(degenerate("its vertices are collinear"))?;

        let dropped = normal.abs().max_position();
        let axes = [(dropped + 1) % 3, (dropped + 2) % 3];
        Ok(Self {
            outline: Box::new(Outline::new(&vertices, axes)),
            vertices: vertices.into_boxed_slice(),
            normal,
            tangent,
        })
    }

    /// The vertices, in the order given.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The unit normal (Newell's, oriented by the vertex order).
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The first vertex, through which the polygon's plane passes.
    fn anchor(&self) -> Vec3 {
        self.vertices[0]
    }

    /// The closest hit in the ray's interval (there is at most one).
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let t = plane_hit(self.anchor(), self.normal, ray)?;
        self.hit_on_plane(ray, t)
    }

    /// The hit at `t`, where `ray` crosses the polygon's plane in its
    /// interval ([`plane_hit`] from the first vertex and the normal), if the
    /// outline holds that point: the rest of [`Polygon::intersect`], for a
    /// caller that has made the plane test already.
    #[inline]
    pub(crate) fn hit_on_plane(&self, ray: &Ray, t: f64) -> Option<ShapeHit> {
        self.outline.contains(ray.at(t)).then(|| ShapeHit::at(t))
    }

    /// True when the ray meets the polygon in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let anchor = self.anchor();
        let (point, point_error) = onto_plane(anchor, self.normal, ray.at(hit.t));
        let offset = point - anchor;
        let bitangent = self.normal.cross(self.tangent);
        LocalSurface {
            point,
            point_error,
            normal: self.normal,
            uv: DVec2::new(offset.dot(self.tangent), offset.dot(bitangent)),
            dpdu: self.tangent,
            dpdv: bitangent,
        }
    }

    /// The bounding box of the surface actually hit: the vertices moved
    /// along the dropped axis onto the plane through `v0` (they may sit off
    /// it by the planarity tolerance), padded by the rounding of that move.
    pub fn bounds(&self) -> Aabb {
        let [ax, ay] = self.outline.axes();
        let dropped = 3 - ax - ay;
        let v0 = self.anchor();
        let n = self.normal;
        let lifted = self.vertices.iter().map(|&v| {
            let mut p = v;
            p[dropped] =
                v0[dropped] - (n[ax] * (v[ax] - v0[ax]) + n[ay] * (v[ay] - v0[ay])) / n[dropped];
            p
        });
        let b = Aabb::from_points(lifted);
        let pad = gamma(8) * b.min.abs().max(b.max.abs());
        Aabb {
            min: b.min - pad,
            max: b.max + pad,
        }
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;

    use super::*;
    use crate::math::random::Rng;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_surface_is_sane, assert_tangents_follow_uv,
    };
    use crate::shape::{Shape, ShapeError};

    fn polygon(points: &[(f64, f64)]) -> Polygon {
        Polygon::new(points.iter().map(|&(x, y)| Vec3::new(x, y, 0.0)).collect()).unwrap()
    }

    fn square() -> Polygon {
        polygon(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
    }

    /// An L: the unit square [0, 2]² without its top-right quarter.
    fn ell() -> Polygon {
        polygon(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ])
    }

    /// A gear-like star of 144 vertices: 72 teeth between radii 0.8 and 1.
    fn gear(center: Vec3, scale: f64) -> Polygon {
        Polygon::new(
            (0..144)
                .map(|k| {
                    let angle = TAU * k as f64 / 144.0;
                    let radius = if k % 2 == 0 { 1.0 } else { 0.8 };
                    center + scale * radius * Vec3::new(angle.cos(), angle.sin(), 0.0)
                })
                .collect(),
        )
        .unwrap()
    }

    fn down_at(x: f64, y: f64) -> Ray {
        Ray::new(Vec3::new(x, y, 2.0), Vec3::new(0.0, 0.0, -0.5))
    }

    #[test]
    fn slightly_non_planar_polygon_far_away_is_hit_only_inside_its_bounds() {
        // Within the coordinate-relative tolerance at x = 1e4: one vertex
        // 0.2 off the plane of the others; the hit surface leaves the box of
        // the vertices, and the bounds must cover it.
        let o = Vec3::new(1e4, 0.0, 0.0);
        let polygon = Polygon::new(vec![
            o,
            o + Vec3::new(1.0, 0.0, 0.0),
            o + Vec3::new(1.0, 1.0, 0.0),
            o + Vec3::new(0.0, 1.0, 0.2),
        ])
        .unwrap();
        let shape = Shape::Polygon(polygon);
        assert_surface_is_sane(&shape, 3);
    }

    #[test]
    fn ray_in_front_hits_with_exact_t_and_normal() {
        let ray = down_at(0.25, 0.75);
        let hit = square().intersect(&ray).unwrap();
        assert_eq!(hit.t, 4.0);
        let s = square().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::Z);
        assert_eq!(s.point, Vec3::new(0.25, 0.75, 0.0));
    }

    #[test]
    fn back_side_is_hit_and_clockwise_vertices_face_down() {
        let up = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        assert_eq!(
            square()
                .surface(&up, &square().intersect(&up).unwrap())
                .normal,
            Vec3::Z
        );
        let clockwise = polygon(&[(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]);
        let hit = clockwise.intersect(&up).unwrap();
        assert_eq!(clockwise.surface(&up, &hit).normal, -Vec3::Z);
    }

    #[test]
    fn polygon_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::Z);
        assert_eq!(square().intersect(&ray), None);
        assert!(!square().occluded(&ray));
    }

    #[test]
    fn ray_passing_beside_is_missed() {
        assert_eq!(square().intersect(&down_at(1.0 + 1e-12, 0.5)), None);
        assert_eq!(square().intersect(&down_at(0.5, -1e-12)), None);
    }

    #[test]
    fn ray_through_the_notch_of_an_l_misses_and_through_its_body_hits() {
        assert_eq!(ell().intersect(&down_at(1.5, 1.5)), None);
        assert_eq!(ell().intersect(&down_at(1.0 + 1e-12, 1.0 + 1e-12)), None);
        for (x, y) in [(0.5, 0.5), (1.5, 0.5), (0.5, 1.5), (1.0 - 1e-12, 1.5)] {
            assert!(ell().intersect(&down_at(x, y)).is_some(), "{x} {y}");
        }
    }

    #[test]
    fn points_level_with_a_vertex_are_classified_by_the_half_open_rule() {
        let diamond = polygon(&[(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)]);
        for (x, inside) in [
            (-1.5, false),
            (-0.5, true),
            (0.0, true),
            (0.5, true),
            (1.5, false),
        ] {
            assert_eq!(diamond.intersect(&down_at(x, 0.0)).is_some(), inside, "{x}");
        }
        // The L's reflex vertex (1, 1) and its neighbours at y = 1.
        for (x, inside) in [(-0.5, false), (0.5, true), (1.5, false), (2.5, false)] {
            assert_eq!(ell().intersect(&down_at(x, 1.0)).is_some(), inside, "{x}");
        }
    }

    #[test]
    fn a_point_on_an_edge_shared_by_two_polygons_is_in_exactly_one() {
        let left = square();
        let right = polygon(&[(1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0)]);
        let diagonal_a = polygon(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]);
        let diagonal_b = polygon(&[(0.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        let mut rng = Rng::new(5);
        for _ in 0..1000 {
            let y = rng.uniform();
            let on_shared_side = down_at(1.0, y);
            let hits = [&left, &right]
                .iter()
                .filter(|p| p.intersect(&on_shared_side).is_some())
                .count();
            assert_eq!(hits, 1, "x = 1, y = {y}");
            let on_diagonal = down_at(y, y);
            let hits = [&diagonal_a, &diagonal_b]
                .iter()
                .filter(|p| p.intersect(&on_diagonal).is_some())
                .count();
            assert_eq!(hits, 1, "x = y = {y}");
        }
    }

    #[test]
    fn gear_with_144_vertices_hits_teeth_and_misses_gaps() {
        let gear = gear(Vec3::ZERO, 1.0);
        let at = |angle: f64, radius: f64| {
            let ray = down_at(radius * angle.cos(), radius * angle.sin());
            gear.intersect(&ray).is_some()
        };
        let step = TAU / 144.0;
        for k in 0..72 {
            let tooth = 2.0 * k as f64 * step;
            let gap = tooth + step;
            assert!(at(tooth, 0.95), "tooth {k}");
            assert!(!at(gap, 0.9), "gap {k}");
            assert!(at(gap, 0.75), "hub at {k}");
            assert!(!at(tooth, 1.01), "outside {k}");
        }
    }

    #[test]
    fn rays_parallel_to_it_or_in_its_plane_miss_without_nan() {
        for ray in [
            Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X),
            Ray::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::X),
            Ray::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
        ] {
            assert_eq!(ell().intersect(&ray), None);
            assert!(!ell().occluded(&ray));
        }
    }

    #[test]
    fn ray_starting_on_the_polygon_does_not_hit_it() {
        let ray = Ray::new(Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.3, 0.2, -1.0));
        assert_eq!(ell().intersect(&ray), None);
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(0.5, 0.5, 2.0), -Vec3::Z, 2.0);
        assert_eq!(square().intersect(&ray), None);
    }

    #[test]
    fn too_few_collinear_or_non_finite_vertices_are_refused() {
        let degenerate = |why| {
            Err(ShapeError::Degenerate {
                shape: "polygon",
                why,
            })
        };
        let few = "it needs at least three vertices";
        let flat = "its vertices are collinear";
        assert_eq!(Polygon::new(vec![]), degenerate(few));
        assert_eq!(Polygon::new(vec![Vec3::ZERO, Vec3::X]), degenerate(few));
        let line = (0..5)
            .map(|i| Vec3::new(0.1, 0.2, 0.3) * i as f64)
            .collect();
        assert_eq!(Polygon::new(line), degenerate(flat));
        assert_eq!(Polygon::new(vec![Vec3::ONE; 4]), degenerate(flat));
        assert_eq!(
            Polygon::new(vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(0.0, f64::INFINITY, 0.0)
            ]),
            Err(ShapeError::NotFinite { what: "vertex" })
        );
    }

    #[test]
    fn a_bow_tie_covers_its_two_lobes_by_the_even_odd_rule() {
        let bow_tie = [[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]]
            .map(|[x, y]| Vec3::new(x, y, 0.0))
            .to_vec();
        let polygon = Polygon::new(bow_tie).unwrap();
        assert_eq!(polygon.normal.abs(), Vec3::Z);
        let hits = |x, y| polygon.occluded(&Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z));
        assert!(hits(1.5, 1.0) && hits(0.5, 1.0));
        assert!(!hits(1.0, 0.3) && !hits(1.0, 1.7));
    }

    #[test]
    fn a_polygon_too_small_to_square_is_refused_as_out_of_range() {
        let tiny = [Vec3::ZERO, Vec3::X, Vec3::Y].map(|v| v * 1e-300).to_vec();
        assert!(matches!(
            Polygon::new(tiny),
            Err(ShapeError::OutOfRange {
                error: magnitude::MagnitudeError::TooSmall { .. },
                ..
            })
        ));
    }

    #[test]
    fn non_planar_vertices_are_refused_naming_the_vertex() {
        let warped = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.1), Vec3::Y];
        assert!(matches!(
            Polygon::new(warped),
            Err(ShapeError::NotPlanar { deviation, .. }) if deviation > 0.01
        ));
    }

    #[test]
    fn six_digit_coordinates_of_a_tilted_polygon_are_planar_enough() {
        let (u, v) = Vec3::new(0.3, -0.5, 0.8).normalize().any_orthonormal_pair();
        let center = Vec3::new(123.456, -78.9, 45.6);
        let six_digits = |x: f64| format!("{x:.5e}").parse::<f64>().unwrap();
        let vertices = (0..144)
            .map(|k| {
                let angle = TAU * k as f64 / 144.0;
                let radius = if k % 2 == 0 { 10.0 } else { 8.0 };
                (center + radius * (angle.cos() * u + angle.sin() * v)).map(six_digits)
            })
            .collect();
        assert!(Polygon::new(vertices).is_ok());
    }

    #[test]
    fn uv_are_world_coordinates_along_the_first_proper_edge() {
        let v0 = Vec3::new(1.0, 2.0, 3.0);
        let shape = Polygon::new(vec![
            v0,
            v0,
            v0 + Vec3::new(2.0, 0.0, 0.0),
            v0 + Vec3::new(2.0, 1.0, 0.0),
            v0 + Vec3::new(0.0, 1.0, 0.0),
        ])
        .unwrap();
        let target = v0 + Vec3::new(0.5, 0.7, 0.0);
        let ray = Ray::new(target + Vec3::Z, -Vec3::Z);
        let s = shape.surface(&ray, &shape.intersect(&ray).unwrap());
        assert!((s.uv - DVec2::new(0.5, 0.7)).length() < 1e-15);
        assert_eq!(s.dpdu, Vec3::X);
    }

    #[test]
    fn secondary_rays_never_hit_the_polygon_they_leave() {
        let (u, v) = Vec3::new(0.3, -0.5, 0.8).normalize().any_orthonormal_pair();
        let tilted_ell = ell()
            .vertices()
            .iter()
            .map(|p| Vec3::new(0.2, 0.1, -0.3) + p.x * u + p.y * v)
            .collect();
        let shapes = [
            ell(),
            Polygon::new(tilted_ell).unwrap(),
            gear(Vec3::ZERO, 1.0),
            gear(Vec3::new(1e4, -1e4, 3e3), 2.0),
            gear(Vec3::new(0.0, 1e-3, 0.0), 1e-3),
            gear(Vec3::ZERO, 1e4),
        ];
        for polygon in shapes {
            let shape = Shape::Polygon(polygon);
            assert_no_self_intersection(&shape, 31);
            assert_surface_is_sane(&shape, 37);
            assert_convex_exits_cleanly(&shape, 39);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        let ray = down_at(0.5, 1.5);
        let s = ell().surface(&ray, &ell().intersect(&ray).unwrap());
        assert_eq!((s.dpdu, s.dpdv), (Vec3::X, Vec3::Y));
        for polygon in [ell(), gear(Vec3::new(1e3, -1e3, 3e2), 2.0)] {
            assert_tangents_follow_uv(&Shape::Polygon(polygon), 13);
        }
    }
}
