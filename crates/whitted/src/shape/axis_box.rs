//! A solid box with faces parallel to the axes, given by two corners.
//!
//! Scene syntax: `shape = "box"`, `min = [x, y, z]`, `max = [x, y, z]`
//! (rotate it with a transform).
//!
//! Parts ([`ShapeHit::part`]) are the faces: 0 at -x, 1 at +x, 2 at -y,
//! 3 at +y, 4 at -z, 5 at +z, each with that outward normal. On the face
//! across axis `i`, `(u, v)` are the coordinates along the next two axes in
//! cyclic order (y, z on the x faces; z, x on the y faces; x, y on the z
//! faces), each scaled to [0, 1] over the face; `dpdu` and `dpdv` are the
//! face's edges along the u and v axes.

use super::{LocalSurface, ShapeError, ShapeHit, finite, not_tiny};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// A box aligned with the axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisBox {
    min: Vec3,
    max: Vec3,
}

impl AxisBox {
    /// The box between the corners `min` and `max`; refused unless `min` is
    /// below `max` on every axis.
    pub fn new(min: Vec3, max: Vec3) -> Result<Self, ShapeError> {
        let min = finite("min", min)?;
        let max = finite("max", max)?;
        if !min.cmplt(max).all() {
            return Err(ShapeError::Degenerate {
                shape: "box",
                why: "min must be below max on every axis",
            });
        }
        not_tiny("the box's shortest side", [(max - min).min_element()])?;
        Ok(Self { min, max })
    }

    /// The smallest corner.
    pub fn min(&self) -> Vec3 {
        self.min
    }

    /// The largest corner.
    pub fn max(&self) -> Vec3 {
        self.max
    }

    /// The slab test: where the ray's line enters and leaves the box, each
    /// with the face it crosses there, or `None` when the line misses. A ray
    /// parallel to a slab is inside it (faces included) or misses; divisions
    /// by a non-zero component never make NaN.
    fn slabs(&self, ray: &Ray) -> Option<((f64, u32), (f64, u32))> {
        let mut near = (f64::NEG_INFINITY, 0);
        let mut far = (f64::INFINITY, 0);
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis], ray.dir[axis]);
            if d == 0.0 {
                if o < self.min[axis] || o > self.max[axis] {
                    return None;
                }
                continue;
            }
            let to_min = ((self.min[axis] - o) / d, 2 * axis as u32);
            let to_max = ((self.max[axis] - o) / d, 2 * axis as u32 + 1);
            let (enter, leave) = if d > 0.0 {
                (to_min, to_max)
            } else {
                (to_max, to_min)
            };
            if enter.0 > near.0 {
                near = enter;
            }
            if leave.0 < far.0 {
                far = leave;
            }
        }
        (near.0 <= far.0).then_some((near, far))
    }

    /// The closest hit in the ray's interval: the face where the ray enters,
    /// or, for a ray starting inside, the face where it leaves.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (near, far) = self.slabs(ray)?;
        [near, far]
            .into_iter()
            .find(|&(t, _)| ray.contains(t))
            .map(|(t, part)| ShapeHit {
                part,
                ..ShapeHit::at(t)
            })
    }

    /// True when the ray meets the box's surface in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit: the face coordinate set to the face's exact
    /// value, the other two clamped to the face. The error bound is
    /// `γ(5)|p|` per axis.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let axis = (hit.part / 2).min(2) as usize;
        let positive = hit.part % 2 == 1;
        let mut point = ray.at(hit.t).clamp(self.min, self.max);
        point[axis] = if positive {
            self.max[axis]
        } else {
            self.min[axis]
        };
        let mut normal = Vec3::ZERO;
        normal[axis] = if positive { 1.0 } else { -1.0 };
        let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
        let extent = self.max - self.min;
        let along = (point - self.min) / extent;
        let (mut dpdu, mut dpdv) = (Vec3::ZERO, Vec3::ZERO);
        dpdu[u_axis] = extent[u_axis];
        dpdv[v_axis] = extent[v_axis];
        LocalSurface {
            point,
            point_error: gamma(5) * point.abs(),
            normal,
            uv: DVec2::new(along[u_axis], along[v_axis]),
            dpdu,
            dpdv,
        }
    }

    /// The bounding box: the box itself.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.min, self.max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_outward_rays_escape, assert_surface_is_sane, assert_tangents_follow_uv, rays_toward,
    };
    use crate::shape::{Shape, ShapeError};

    /// The cube [-1, 1]³.
    fn cube() -> AxisBox {
        AxisBox::new(Vec3::splat(-1.0), Vec3::ONE).unwrap()
    }

    #[test]
    fn rays_from_each_side_hit_that_face_with_exact_t_and_normal() {
        let axes = [Vec3::X, Vec3::Y, Vec3::Z];
        for (part, normal) in [
            (0, -Vec3::X),
            (1, Vec3::X),
            (2, -Vec3::Y),
            (3, Vec3::Y),
            (4, -Vec3::Z),
            (5, Vec3::Z),
        ] {
            let across = axes[(part as usize / 2 + 1) % 3];
            let origin = 5.0 * normal + 0.25 * across;
            let ray = Ray::new(origin, -2.0 * normal);
            let hit = cube().intersect(&ray).unwrap();
            assert_eq!((hit.t, hit.part), (2.0, part));
            let s = cube().surface(&ray, &hit);
            assert_eq!(s.normal, normal);
            assert_eq!(s.point, normal + 0.25 * across);
        }
    }

    #[test]
    fn ray_starting_inside_hits_the_exit_face_with_outward_normal() {
        let ray = Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.5, -0.25));
        let hit = cube().intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (1.0, 1));
        let s = cube().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::X);
        assert_eq!(s.point, Vec3::new(1.0, 0.5, -0.25));
        let down = Ray::new(Vec3::new(0.3, -0.2, 0.5), -Vec3::Z);
        let hit = cube().intersect(&down).unwrap();
        assert_eq!((hit.t, hit.part), (1.5, 4));
    }

    #[test]
    fn box_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert_eq!(cube().intersect(&ray), None);
        assert!(!cube().occluded(&ray));
    }

    #[test]
    fn axis_parallel_rays_beside_a_face_miss_and_inside_it_hit() {
        for (y, z) in [(1.0 + 1e-12, 0.0), (0.0, -1.0 - 1e-12), (2.0, 2.0)] {
            let ray = Ray::new(Vec3::new(-5.0, y, z), Vec3::X);
            assert_eq!(cube().intersect(&ray), None, "{y} {z}");
        }
        let ray = Ray::new(Vec3::new(-5.0, 1.0 - 1e-12, 0.0), Vec3::X);
        assert_eq!(cube().intersect(&ray).unwrap().part, 0);
    }

    #[test]
    fn rays_along_a_face_edge_or_through_a_corner_give_no_nan() {
        for (origin, dir) in [
            (Vec3::new(-5.0, 1.0, 0.0), Vec3::X),
            (Vec3::new(-5.0, 1.0, 1.0), Vec3::X),
            (Vec3::new(1.0, 0.0, 0.0), Vec3::Y),
            (Vec3::splat(-5.0), Vec3::ONE),
            (Vec3::new(-3.0, -3.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
        ] {
            let ray = Ray::new(origin, dir);
            if let Some(hit) = cube().intersect(&ray) {
                let s = cube().surface(&ray, &hit);
                assert!(s.point.is_finite() && s.uv.is_finite() && s.normal.is_finite());
                assert_eq!(s.normal.length(), 1.0);
            }
        }
        let corner = Ray::new(Vec3::splat(-5.0), Vec3::ONE);
        let hit = cube().intersect(&corner).unwrap();
        assert_eq!(hit.t, 4.0);
        assert_eq!(cube().surface(&corner, &hit).point, Vec3::splat(-1.0));
    }

    #[test]
    fn ray_starting_on_a_face_leaving_misses_and_entering_hits_the_far_face() {
        let leaving = Ray::new(Vec3::new(1.0, 0.2, 0.3), Vec3::new(1.0, 0.5, 0.0));
        assert_eq!(cube().intersect(&leaving), None);
        let entering = Ray::new(Vec3::new(1.0, 0.2, 0.3), -Vec3::X);
        let hit = cube().intersect(&entering).unwrap();
        assert_eq!((hit.t, hit.part), (2.0, 0));
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 4.0);
        assert_eq!(cube().intersect(&ray), None);
        let inside = Ray::segment(Vec3::ZERO, Vec3::Z, 1.0);
        assert_eq!(cube().intersect(&inside), None);
    }

    #[test]
    fn flat_inverted_or_non_finite_boxes_are_refused() {
        let degenerate = Err(ShapeError::Degenerate {
            shape: "box",
            why: "min must be below max on every axis",
        });
        assert_eq!(
            AxisBox::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)),
            degenerate
        );
        assert_eq!(AxisBox::new(Vec3::ONE, Vec3::ZERO), degenerate);
        assert_eq!(
            AxisBox::new(Vec3::ZERO, Vec3::new(1.0, f64::NAN, 1.0)),
            Err(ShapeError::NotFinite { what: "max" })
        );
    }

    #[test]
    fn uv_run_over_each_face_in_cyclic_axis_order() {
        let shape = AxisBox::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 4.0, 8.0)).unwrap();
        for (origin, dir, part, uv, dpdu) in [
            (
                Vec3::new(5.0, 1.0, 6.0),
                -Vec3::X,
                1,
                (0.25, 0.75),
                Vec3::new(0.0, 4.0, 0.0),
            ),
            (
                Vec3::new(0.5, -5.0, 2.0),
                Vec3::Y,
                2,
                (0.25, 0.25),
                Vec3::new(0.0, 0.0, 8.0),
            ),
            (
                Vec3::new(1.5, 1.0, 9.0),
                -Vec3::Z,
                5,
                (0.75, 0.25),
                Vec3::new(2.0, 0.0, 0.0),
            ),
        ] {
            let ray = Ray::new(origin, dir);
            let hit = shape.intersect(&ray).unwrap();
            assert_eq!(hit.part, part);
            let s = shape.surface(&ray, &hit);
            assert_eq!(s.uv, DVec2::new(uv.0, uv.1));
            assert_eq!(s.dpdu, dpdu);
        }
    }

    #[test]
    fn rays_entering_through_an_edge_never_slip_between_faces() {
        let mut rng = Rng::new(139);
        for (min, max) in [
            (Vec3::splat(-1.0), Vec3::ONE),
            (Vec3::new(0.1, -0.3, 0.7), Vec3::new(0.4, 2.9, 0.8)),
            (
                Vec3::new(1e4, -2e4, 3e4),
                Vec3::new(1e4 + 2.0, -2e4 + 0.5, 3e4 + 1.0),
            ),
        ] {
            let shape = AxisBox::new(min, max).unwrap();
            let mut entering = 0;
            for _ in 0..20_000 {
                // An edge runs along `axis`; it is where the faces across
                // the two other axes meet.
                let axis = rng.below(3) as usize;
                let mut rim = rng.point_in(min, max);
                let mut normals = [Vec3::ZERO; 2];
                for (k, normal) in normals.iter_mut().enumerate() {
                    let across = (axis + 1 + k) % 3;
                    let high = rng.uniform() < 0.5;
                    rim[across] = if high { max[across] } else { min[across] };
                    normal[across] = if high { 1.0 } else { -1.0 };
                }
                let dir = rng.unit_vector();
                if normals.iter().any(|n| dir.dot(*n) > -0.01) {
                    continue;
                }
                entering += 1;
                let ray = Ray::new(rim - 3.0 * (max - min).length() * dir, dir);
                assert!(shape.intersect(&ray).is_some(), "{ray:?}");
            }
            assert!(entering > 2000, "{entering}");
        }
    }

    #[test]
    fn rays_leaving_points_near_edges_and_corners_escape() {
        for (min, max) in [
            (Vec3::splat(-1.0), Vec3::ONE),
            (
                Vec3::new(1e4, -2e4, 3e4),
                Vec3::new(1e4 + 2.0, -2e4 + 0.5, 3e4 + 1.0),
            ),
            (Vec3::ZERO, Vec3::new(1e-3, 2e-3, 5e-4)),
        ] {
            let shape = AxisBox::new(min, max).unwrap();
            let corners = shape.bounds().corners();
            let targets: Vec<Vec3> = (0..2000)
                .map(|k| {
                    let (a, b) = (corners[k % 8], corners[(k / 8) % 8]);
                    let s = (k % 7) as f64 / 6.0;
                    a + s * (b - a)
                })
                .collect();
            let size = (max - min).length();
            let rays = rays_toward(&targets, 3.0 * size, 101);
            let hits = assert_outward_rays_escape(&Shape::AxisBox(shape), rays, 103);
            assert!(hits > 500, "{hits}");
        }
    }

    #[test]
    fn secondary_rays_never_hit_the_box_they_leave() {
        for (min, max) in [
            (Vec3::splat(-1.0), Vec3::ONE),
            (Vec3::new(0.2, 0.5, -3.0), Vec3::new(0.3, 4.0, 1.0)),
            (
                Vec3::new(1e4, 1e4, -1e4),
                Vec3::new(1e4 + 1.0, 1e4 + 2.0, -1e4 + 3.0),
            ),
            (Vec3::new(-1e-3, 0.0, 0.0), Vec3::new(1e-3, 1e-3, 2e-3)),
            (Vec3::splat(-1e4), Vec3::new(2e4, 1e4, 3e4)),
        ] {
            let shape = Shape::AxisBox(AxisBox::new(min, max).unwrap());
            assert_no_self_intersection(&shape, 107);
            assert_surface_is_sane(&shape, 109);
            assert_convex_exits_cleanly(&shape, 113);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        for (min, max) in [
            (Vec3::splat(-1.0), Vec3::ONE),
            (Vec3::new(0.2, 0.5, -3.0), Vec3::new(0.3, 4.0, 1.0)),
        ] {
            let shape = Shape::AxisBox(AxisBox::new(min, max).unwrap());
            assert_tangents_follow_uv(&shape, 29);
        }
    }
}
