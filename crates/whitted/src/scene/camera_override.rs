//! Replacing parts of a scene's camera, whatever format the scene came
//! from: any part given replaces the scene's, the others are kept.

use crate::math::Vec3;
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
}
