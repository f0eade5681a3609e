//! The pinhole camera.
//!
//! Scene syntax (`[camera]`): `eye`, `look_at`, `up` (points and a vector) and
//! `fov`, the vertical field of view in degrees from the top edge of the
//! image to the bottom edge. Primary rays start at the eye and pass through
//! pixel centres: pixel `(column, row)` is centred at `(column + 0.5,
//! row + 0.5)` in image coordinates, row 0 at the top.

use crate::math::magnitude::{self, MagnitudeError};
use crate::math::{Aabb, DVec2, Ray, Vec3, unit};
use crate::shading::RayDifferential;

/// Why a camera could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraError {
    /// `eye` and `look_at` are the same point.
    #[error("the camera's eye and look_at are the same point")]
    NoViewDirection,
    /// `up` is zero or parallel to the view direction.
    #[error("the camera's up vector is zero or parallel to the view direction")]
    BadUp,
    /// The field of view is not inside (0°, 180°).
    #[error("the field of view must be between 0 and 180 degrees, got {0}")]
    BadFov(f64),
    /// A value that is not a finite number.
    #[error("the camera has a value that is not a finite number")]
    NotFinite,
    /// `eye` or `look_at` beyond ±[`magnitude::MAX_COORDINATE`]: its rays
    /// would meet the scene's shapes in squares that overflow.
    #[error("the camera's {what} is out of range: {error}")]
    OutOfRange {
        /// `eye` or `look_at`.
        what: &'static str,
        /// How it is out of range.
        error: MagnitudeError,
    },
    /// A model to frame whose size is out of range.
    #[error("the model's size is out of range: {0}")]
    ModelOutOfRange(MagnitudeError),
}

/// The fraction of a model's largest side below which [`Camera::framing`]
/// takes it as flat along an axis.
pub const THIN: f64 = 0.1;

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    eye: Vec3,
    look_at: Vec3,
    up: Vec3,
    fov_degrees: f64,
    forward: Vec3,
    right: Vec3,
    true_up: Vec3,
    tan_half_fov: f64,
}

impl Camera {
    /// A camera at `eye` looking at `look_at`, with `up` pointing up on the
    /// image and a vertical field of view of `fov_degrees`.
    pub fn new(eye: Vec3, look_at: Vec3, up: Vec3, fov_degrees: f64) -> Result<Self, CameraError> {
        if !(eye.is_finite() && look_at.is_finite() && up.is_finite() && fov_degrees.is_finite()) {
            return Err(CameraError::NotFinite);
        }
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(CameraError::BadFov(fov_degrees));
        }
        for (what, point) in [("eye", eye), ("look_at", look_at)] {
            magnitude::point(point).map_err(|error| CameraError::OutOfRange { what, error })?;
        }
        let forward = unit(look_at - eye).ok_or(CameraError::NoViewDirection)?;
        let side = forward.cross(unit(up).ok_or(CameraError::BadUp)?);
        if side.length() <= 1e-9 {
            return Err(CameraError::BadUp);
        }
        let right = side.normalize();
        let true_up = right.cross(forward);
        Ok(Self {
            eye,
            look_at,
            up,
            fov_degrees,
            forward,
            right,
            true_up,
            tan_half_fov: (0.5 * fov_degrees).to_radians().tan(),
        })
    }

    /// A camera looking at the centre of `bounds` along its diagonal, from
    /// the nearest distance at which all eight corners project inside an
    /// image of the given aspect ratio (width / height), with `up` = +y.
    /// This is the default view of the Embree anchor harness, so both trace
    /// the same primary rays.
    ///
    /// A flat or thin model would be seen edge-on along its diagonal (a
    /// quad in z = 0 has its diagonal in its plane): an axis along which
    /// the box is thinner than [`THIN`] of its largest side counts as long
    /// as that side in the view direction, so such a model is seen from
    /// its normal side, at 35° from a square's plane.
    pub fn framing(bounds: &Aabb, aspect: f64, fov_degrees: f64) -> Result<Self, CameraError> {
        if bounds.is_empty() || !bounds.is_finite() {
            return Err(CameraError::NotFinite);
        }
        for corner in [bounds.min, bounds.max] {
            magnitude::point(corner).map_err(CameraError::ModelOutOfRange)?;
        }
        let c = bounds.centroid();
        let extent = bounds.extent();
        let largest = extent.max_element();
        let seen = extent.map(|side| if side < THIN * largest { largest } else { side });
        let diagonal = unit(seen).ok_or(CameraError::NoViewDirection)?;
        let forward = -diagonal;
        let right = unit(forward.cross(Vec3::Y)).ok_or(CameraError::BadUp)?;
        let up = right.cross(forward);
        let th = (0.5 * fov_degrees).to_radians().tan();
        let distance = bounds
            .corners()
            .iter()
            .map(|q| {
                let v = *q - c;
                let spread = (v.dot(right).abs() / (th * aspect)).max(v.dot(up).abs() / th);
                spread - v.dot(forward)
            })
            .fold(f64::NEG_INFINITY, f64::max);
        Self::new(c + diagonal * distance, c, Vec3::Y, fov_degrees)
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The point looked at.
    pub fn look_at(&self) -> Vec3 {
        self.look_at
    }

    /// The up vector as given.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// The vertical field of view in degrees.
    pub fn fov_degrees(&self) -> f64 {
        self.fov_degrees
    }

    /// The unit-length primary ray through image position `(x, y)` of a
    /// `width` × `height` image, in pixel units from the top-left corner.
    #[inline]
    pub fn ray(&self, width: u32, height: u32, x: f64, y: f64) -> Ray {
        let aspect = f64::from(width) / f64::from(height);
        let sx = (2.0 * x / f64::from(width) - 1.0) * aspect * self.tan_half_fov;
        let sy = (1.0 - 2.0 * y / f64::from(height)) * self.tan_half_fov;
        let dir = (self.forward + sx * self.right + sy * self.true_up).normalize();
        Ray::new(self.eye, dir)
    }

    /// [`Camera::ray`] through each of `positions`, into the same place
    /// of `rays`: the same rays bit for bit (the same operations in the
    /// same order). With AVX, four rays are computed side by side in its
    /// lanes, so that their divisions and square roots share the divider
    /// rather than queue for it one ray after the other.
    ///
    /// # Panics
    ///
    /// When `rays` is shorter than `positions`.
    pub fn rays(&self, width: u32, height: u32, positions: &[DVec2], rays: &mut [Ray]) {
        assert!(
            rays.len() >= positions.len(),
            "room for {} rays",
            rays.len()
        );
        #[cfg(target_arch = "x86_64")]
        if crate::accel::Backend::current().has_avx() {
            // SAFETY: the processor has AVX (the current backend does).
            return unsafe { self.rays_avx(width, height, positions, rays) };
        }
        for (p, ray) in positions.iter().zip(rays) {
            *ray = self.ray(width, height, p.x, p.y);
        }
    }

    /// [`Self::rays`], four at a time in AVX lanes: each operation of
    /// [`Self::ray`] in its order, on four rays at once.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn rays_avx(&self, width: u32, height: u32, positions: &[DVec2], rays: &mut [Ray]) {
        use std::arch::x86_64::{
            __m256d, _mm256_add_pd, _mm256_div_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd,
            _mm256_sqrt_pd, _mm256_storeu_pd, _mm256_sub_pd,
        };
        let (w, h) = (f64::from(width), f64::from(height));
        let aspect = w / h;
        let one = _mm256_set1_pd(1.0);
        let two = _mm256_set1_pd(2.0);
        let t = _mm256_set1_pd(self.tan_half_fov);
        let store = |v: __m256d| {
            let mut lanes = [0.0; 4];
            // SAFETY: `lanes` is four writable `f64`s; the store is
            // unaligned.
            unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), v) };
            lanes
        };
        for (chunk, out) in positions.chunks(4).zip(rays.chunks_mut(4)) {
            // Lanes past the chunk look through the image's centre.
            let (mut xs, mut ys) = ([0.5 * w; 4], [0.5 * h; 4]);
            for (i, p) in chunk.iter().enumerate() {
                (xs[i], ys[i]) = (p.x, p.y);
            }
            // SAFETY: `xs` and `ys` are four readable `f64`s each; the
            // loads are unaligned.
            let (x, y) = unsafe { (_mm256_loadu_pd(xs.as_ptr()), _mm256_loadu_pd(ys.as_ptr())) };
            let sx = _mm256_sub_pd(_mm256_div_pd(_mm256_mul_pd(two, x), _mm256_set1_pd(w)), one);
            let sx = _mm256_mul_pd(_mm256_mul_pd(sx, _mm256_set1_pd(aspect)), t);
            let sy = _mm256_div_pd(_mm256_mul_pd(two, y), _mm256_set1_pd(h));
            let sy = _mm256_mul_pd(_mm256_sub_pd(one, sy), t);
            let v = [0, 1, 2].map(|a| {
                let along = _mm256_add_pd(
                    _mm256_set1_pd(self.forward[a]),
                    _mm256_mul_pd(sx, _mm256_set1_pd(self.right[a])),
                );
                _mm256_add_pd(along, _mm256_mul_pd(sy, _mm256_set1_pd(self.true_up[a])))
            });
            let square = |c: __m256d| _mm256_mul_pd(c, c);
            let length = _mm256_add_pd(_mm256_add_pd(square(v[0]), square(v[1])), square(v[2]));
            let scale = _mm256_div_pd(one, _mm256_sqrt_pd(length));
            let d = v.map(|c| _mm256_mul_pd(c, scale));
            let (d, inv) = (d.map(store), d.map(|c| store(_mm256_div_pd(one, c))));
            for (i, ray) in out.iter_mut().take(chunk.len()).enumerate() {
                *ray = Ray {
                    origin: self.eye,
                    dir: Vec3::new(d[0][i], d[1][i], d[2][i]),
                    inv_dir: Vec3::new(inv[0][i], inv[1][i], inv[2][i]),
                    t_min: 0.0,
                    t_max: f64::INFINITY,
                };
            }
        }
    }

    /// The ray differential of [`Camera::ray`] at `(x, y)`: how its
    /// direction changes per pixel step in x and y (its origin does not).
    pub fn ray_differential(&self, width: u32, height: u32, x: f64, y: f64) -> RayDifferential {
        let aspect = f64::from(width) / f64::from(height);
        let sx = (2.0 * x / f64::from(width) - 1.0) * aspect * self.tan_half_fov;
        let sy = (1.0 - 2.0 * y / f64::from(height)) * self.tan_half_fov;
        let v = self.forward + sx * self.right + sy * self.true_up;
        let (length, d) = (v.length(), v.normalize());
        // ∂(v/|v|) = (∂v − (d·∂v) d) / |v|.
        let unit = |dv: Vec3| (dv - d.dot(dv) * d) / length;
        let dvdx = self.right * (2.0 * aspect * self.tan_half_fov / f64::from(width));
        let dvdy = self.true_up * (-2.0 * self.tan_half_fov / f64::from(height));
        RayDifferential {
            dox: Vec3::ZERO,
            ddx: unit(dvdx),
            doy: Vec3::ZERO,
            ddy: unit(dvdy),
        }
    }

    /// Where `point` appears on a `width` × `height` image (pixel units
    /// from the top-left corner, the inverse of [`Camera::ray`]), and its
    /// depth along the view direction; the position means something only
    /// where the depth is positive (in front of the eye).
    pub fn project(&self, width: u32, height: u32, point: Vec3) -> (DVec2, f64) {
        let d = point - self.eye;
        let depth = d.dot(self.forward);
        let aspect = f64::from(width) / f64::from(height);
        let sx = d.dot(self.right) / depth;
        let sy = d.dot(self.true_up) / depth;
        let x = (sx / (aspect * self.tan_half_fov) + 1.0) * f64::from(width) / 2.0;
        let y = (1.0 - sy / self.tan_half_fov) * f64::from(height) / 2.0;
        (DVec2::new(x, y), depth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projecting_a_point_on_a_pixel_s_ray_gives_that_pixel() {
        let c = camera();
        for (x, y) in [(0.5, 0.5), (199.25, 13.0), (100.0, 99.5)] {
            let ray = c.ray(200, 100, x, y);
            let (at, depth) = c.project(200, 100, ray.at(7.5));
            assert!(
                (at.x - x).abs() < 1e-9 && (at.y - y).abs() < 1e-9,
                "{at} for {x},{y}"
            );
            assert!(depth > 0.0);
        }
        let behind = c.project(200, 100, c.ray(200, 100, 10.0, 10.0).at(-1.0)).1;
        assert!(behind < 0.0);
    }

    /// Without AVX `Camera::rays` is `Camera::ray` itself: nothing to
    /// compare.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn rays_made_a_row_at_a_time_are_the_rays_made_one_by_one() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let mut rng = crate::math::random::Rng::new(5);
        for case in 0..2000 {
            let eye = rng.point_in(Vec3::splat(-100.0), Vec3::splat(100.0));
            let look_at = rng.point_in(Vec3::splat(-10.0), Vec3::splat(10.0));
            let Ok(c) = Camera::new(eye, look_at, rng.unit_vector(), rng.range(1.0, 170.0)) else {
                continue;
            };
            let (w, h) = (1 + rng.below(3000), 1 + rng.below(3000));
            let count = case % 20;
            let positions: Vec<DVec2> = (0..count)
                .map(|_| DVec2::new(rng.range(0.0, f64::from(w)), rng.range(0.0, f64::from(h))))
                .collect();
            let mut rays = vec![Ray::new(Vec3::ZERO, Vec3::X); count];
            c.rays(w, h, &positions, &mut rays);
            for (p, ray) in positions.iter().zip(&rays) {
                let alone = format!("{:?}", c.ray(w, h, p.x, p.y));
                assert_eq!(format!("{ray:?}"), alone, "{p} of {w}x{h}");
            }
        }
    }

    #[test]
    fn the_ray_differential_matches_neighbouring_pixel_rays() {
        let c = Camera::new(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y, 50.0).unwrap();
        let (w, h) = (320, 200);
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (300.25, 17.5), (3.0, 190.0)] {
            let d = c.ray_differential(w, h, x, y);
            let e = 1e-4;
            let fx = (c.ray(w, h, x + e, y).dir - c.ray(w, h, x - e, y).dir) / (2.0 * e);
            let fy = (c.ray(w, h, x, y + e).dir - c.ray(w, h, x, y - e).dir) / (2.0 * e);
            assert!(
                (d.ddx - fx).length() < 1e-8 * fx.length().max(1e-3),
                "{d:?} {fx}"
            );
            assert!(
                (d.ddy - fy).length() < 1e-8 * fy.length().max(1e-3),
                "{d:?} {fy}"
            );
            // A whole pixel step agrees to first order.
            let step = c.ray(w, h, x + 1.0, y).dir - c.ray(w, h, x, y).dir;
            assert!((d.ddx - step).length() < 0.01 * step.length());
            assert_eq!((d.dox, d.doy), (Vec3::ZERO, Vec3::ZERO));
        }
    }

    fn camera() -> Camera {
        Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 90.0).unwrap()
    }

    #[test]
    fn centre_of_an_odd_image_looks_straight_ahead() {
        let r = camera().ray(3, 3, 1.5, 1.5);
        assert!((r.dir - -Vec3::Z).length() < 1e-15);
        assert_eq!(r.origin, Vec3::new(0.0, 0.0, 5.0));
    }

    #[test]
    fn row_zero_is_the_top_and_column_zero_the_left() {
        let c = camera();
        let top_left = c.ray(100, 100, 0.0, 0.0).dir;
        assert!(top_left.y > 0.0 && top_left.x < 0.0);
        // A 90° field of view reaches 45° at the top edge.
        let top = c.ray(100, 100, 50.0, 0.0).dir;
        assert!((top.y - (-top.z)).abs() < 1e-12);
    }

    #[test]
    fn looking_along_plus_z_with_y_up_puts_plus_x_on_the_left() {
        // The convention stated in docs/scene-format.md: a right-handed world.
        let c = Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0).unwrap();
        assert!(c.ray(100, 100, 0.0, 50.0).dir.x > 0.0);
        assert!(c.ray(100, 100, 100.0, 50.0).dir.x < 0.0);
    }

    #[test]
    fn wide_images_widen_the_horizontal_view() {
        let right = camera().ray(200, 100, 200.0, 50.0).dir;
        assert!((right.x / -right.z - 2.0).abs() < 1e-12);
    }

    #[test]
    fn framing_keeps_every_corner_in_view_and_touches_the_frame() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 1.0, 0.5));
        let c = Camera::framing(&bounds, 1.5, 50.0).unwrap();
        let th = 25f64.to_radians().tan();
        let mut widest: f64 = 0.0;
        for q in bounds.corners() {
            let v = q - c.eye;
            let depth = v.dot(c.forward);
            let x = v.dot(c.right) / depth / (th * 1.5);
            let y = v.dot(c.true_up) / depth / th;
            assert!(x.abs() <= 1.0 + 1e-12 && y.abs() <= 1.0 + 1e-12);
            widest = widest.max(x.abs()).max(y.abs());
        }
        assert!((widest - 1.0).abs() < 1e-12);
        assert!((c.forward + bounds.extent().normalize()).length() < 1e-12);
    }

    #[test]
    fn tiny_and_far_view_directions_and_huge_up_vectors_are_accepted() {
        let straight = camera().ray(3, 3, 1.5, 1.5).dir;
        for (eye, look_at, up) in [
            (Vec3::ZERO, Vec3::new(0.0, 0.0, -1e-200), Vec3::Y),
            (Vec3::ZERO, Vec3::new(0.0, 0.0, -1e30), Vec3::Y),
            (
                Vec3::new(0.0, 0.0, 1e30),
                Vec3::new(0.0, 0.0, -1e30),
                Vec3::Y,
            ),
            (Vec3::ZERO, -Vec3::Z, Vec3::new(0.0, 1e-200, 0.0)),
            (Vec3::ZERO, -Vec3::Z, Vec3::new(0.0, 1e200, 0.0)),
        ] {
            let c = Camera::new(eye, look_at, up, 90.0).unwrap();
            let dir = c.ray(3, 3, 1.5, 1.5).dir;
            assert!((dir - straight).length() < 1e-15, "{look_at} {up}: {dir}");
            let right = c.ray(3, 3, 3.0, 1.5).dir;
            assert!(right.x > 0.0, "{look_at} {up}: {right}");
        }
    }

    #[test]
    fn a_flat_model_is_framed_from_its_normal_side() {
        let quad = Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0));
        let c = Camera::framing(&quad, 1.0, 50.0).unwrap();
        let centre = c.ray(3, 3, 1.5, 1.5);
        assert!(centre.dir.z < -0.5, "{}", centre.dir);
        let thin = Aabb::new(Vec3::ZERO, Vec3::new(4.0, 0.01, 4.0));
        let c = Camera::framing(&thin, 1.0, 50.0).unwrap();
        assert!(c.ray(3, 3, 1.5, 1.5).dir.y < -0.5);
    }

    #[test]
    fn out_of_range_cameras_and_models_are_refused_as_such() {
        let huge = Vec3::splat(3e38);
        assert_eq!(
            Camera::new(huge, Vec3::ZERO, Vec3::Y, 45.0),
            Err(CameraError::OutOfRange {
                what: "eye",
                error: MagnitudeError::TooLarge { value: 3e38 }
            })
        );
        let model = Aabb::new(Vec3::splat(-1e308), Vec3::splat(1e308));
        assert_eq!(
            Camera::framing(&model, 1.0, 50.0),
            Err(CameraError::ModelOutOfRange(MagnitudeError::TooLarge {
                value: -1e308
            }))
        );
    }

    #[test]
    fn bad_cameras_are_refused() {
        assert_eq!(
            Camera::new(Vec3::ONE, Vec3::ONE, Vec3::Y, 45.0),
            Err(CameraError::NoViewDirection)
        );
        assert_eq!(
            Camera::new(Vec3::ZERO, Vec3::Y, Vec3::Y, 45.0),
            Err(CameraError::BadUp)
        );
        assert_eq!(
            Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 180.0),
            Err(CameraError::BadFov(180.0))
        );
    }
}
