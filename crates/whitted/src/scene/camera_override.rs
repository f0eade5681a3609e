//! Replacing parts of a scene's camera, whatever format the scene came
//! from: any part given replaces the scene's, the others are kept.

use crate::math::{Vec3, magnitude, unit};
use crate::render::{Camera, CameraError};

/// The parts of a camera to replace; `None` keeps the scene's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraOverride {
    /// Where the eye is.
    pub eye: Option<Vec3>,
    /// The point looked at.
    pub look_at: Option<Vec3>,
    /// The direction that is up on the image.
    pub up: Option<Vec3>,
    /// The vertical field of view, in degrees.
    pub fov_degrees: Option<f64>,
}

impl CameraOverride {
    /// True when nothing is replaced.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// Refuses, without any scene, what no camera could accept: a field of
    /// view outside (0, 180) degrees, a non-finite part, a zero `up`, an
    /// eye on the point looked at, or (all three given) an `up` along the
    /// view. What depends on the scene's camera is checked by [`apply`].
    ///
    /// [`apply`]: CameraOverride::apply
    pub fn check(&self) -> Result<(), CameraError> {
        let finite = |v: Option<Vec3>| v.is_none_or(|v| v.is_finite());
        if !(finite(self.eye)
            && finite(self.look_at)
            && finite(self.up)
            && self.fov_degrees.is_none_or(f64::is_finite))
        {
            return Err(CameraError::NotFinite);
        }
        for (what, point) in [("eye", self.eye), ("look_at", self.look_at)] {
            if let Some(point) = point {
                magnitude::point(point).map_err(|error| CameraError::OutOfRange { what, error })?;
            }
        }
        if self.up.is_some_and(|up| unit(up).is_none()) {
            return Err(CameraError::BadUp);
        }
        // Stand-ins for the parts not given, which no check refuses: a view
        // across `up`, an `up` across the view.
        let (eye, look_at) = match (self.eye, self.look_at) {
            (Some(eye), Some(look_at)) => (eye, look_at),
            _ => (
                Vec3::ZERO,
                self.up.map_or(Vec3::Z, Vec3::any_orthogonal_vector),
            ),
        };
        let up = self.up.unwrap_or_else(|| {
            let view = look_at - eye;
            let view = if view.is_finite() {
                view
            } else {
                0.5 * look_at - 0.5 * eye
            };
            view.any_orthogonal_vector()
        });
        Camera::new(eye, look_at, up, self.fov_degrees.unwrap_or(45.0)).map(|_| ())
    }

    /// `camera` with the given parts replaced, checked like any camera.
    pub fn apply(&self, camera: &Camera) -> Result<Camera, CameraError> {
        if self.is_empty() {
            return Ok(camera.clone());
        }
        Camera::new(
            self.eye.unwrap_or(camera.eye()),
            self.look_at.unwrap_or(camera.look_at()),
            self.up.unwrap_or(camera.up()),
            self.fov_degrees.unwrap_or(camera.fov_degrees()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn given_parts_replace_and_missing_parts_are_kept() {
        let camera = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        assert_eq!(CameraOverride::default().apply(&camera), Ok(camera.clone()));
        let moved = CameraOverride {
            eye: Some(Vec3::new(0.0, 0.0, 5.0)),
            fov_degrees: Some(60.0),
            ..CameraOverride::default()
        }
        .apply(&camera)
        .unwrap();
        assert_eq!(moved.eye(), Vec3::new(0.0, 0.0, 5.0));
        assert_eq!((moved.look_at(), moved.up()), (Vec3::ZERO, Vec3::Y));
        assert_eq!(moved.fov_degrees(), 60.0);
    }

    #[test]
    fn an_invalid_result_is_refused() {
        let camera = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        let onto_itself = CameraOverride {
            look_at: Some(Vec3::Z),
            ..CameraOverride::default()
        };
        assert_eq!(
            onto_itself.apply(&camera),
            Err(CameraError::NoViewDirection)
        );
    }

    #[test]
    fn what_no_camera_accepts_is_refused_without_a_scene() {
        let given = |eye, look_at, up, fov_degrees| CameraOverride {
            eye,
            look_at,
            up,
            fov_degrees,
        };
        let far = Vec3::splat(magnitude::MAX_COORDINATE);
        for fine in [
            CameraOverride::default(),
            given(Some(Vec3::Z), None, None, None),
            given(None, Some(far), None, None),
            given(Some(-far), None, Some(Vec3::Y), None),
            given(Some(far), Some(-far), None, None),
            given(Some(Vec3::splat(1e-300)), Some(Vec3::ZERO), None, None),
            given(None, None, Some(Vec3::new(0.0, 1e-200, 0.0)), Some(179.0)),
            given(Some(Vec3::Z), Some(Vec3::ZERO), Some(Vec3::Y), Some(1.0)),
        ] {
            assert_eq!(fine.check(), Ok(()), "{fine:?}");
        }
        for (wrong, error) in [
            (given(None, None, None, Some(0.0)), CameraError::BadFov(0.0)),
            (
                given(None, None, None, Some(180.0)),
                CameraError::BadFov(180.0),
            ),
            (
                given(None, None, Some(Vec3::ZERO), None),
                CameraError::BadUp,
            ),
            (
                given(Some(Vec3::Z), Some(Vec3::Z), None, None),
                CameraError::NoViewDirection,
            ),
            (
                given(Some(Vec3::Z), Some(Vec3::ZERO), Some(Vec3::Z), None),
                CameraError::BadUp,
            ),
            (
                given(Some(Vec3::splat(f64::INFINITY)), None, None, None),
                CameraError::NotFinite,
            ),
            (
                given(Some(Vec3::splat(3e38)), None, None, None),
                CameraError::OutOfRange {
                    what: "eye",
                    error: magnitude::point(Vec3::splat(3e38)).unwrap_err(),
                },
            ),
            (
                given(None, Some(-2.0 * far), None, None),
                CameraError::OutOfRange {
                    what: "look_at",
                    error: magnitude::point(-2.0 * far).unwrap_err(),
                },
            ),
        ] {
            assert_eq!(wrong.check(), Err(error), "{wrong:?}");
        }
    }
}
