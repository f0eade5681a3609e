//! The `v` block: the camera and the image size.
//!
//! ```text
//! v
//! from 2.1 1.3 1.7
//! at 0 0 0
//! up 0 0 1
//! angle 45
//! hither 0.01
//! resolution 512 512
//! ```
//!
//! NFF's `angle` spans the centres of the first and last pixel rows, where
//! our camera's field of view spans the image's edges; [`edge_to_edge_fov`]
//! converts. The camera basis is NFF's: `right = forward × up`, and image y
//! grows along `right × forward`. `hither` is read and checked but not used:
//! every ray starts at the eye.

use std::ops::Range;

use super::reader::{Parsed, Reader};
use crate::math::Vec3;
use crate::render::{Camera, CameraError};
use crate::render::{MAX_SIDE, check_image_size};

/// What the `v` block says.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct View {
    /// The camera, with our edge-to-edge field of view.
    pub(super) camera: Camera,
    /// Image width in pixels.
    pub(super) width: u32,
    /// Image height in pixels.
    pub(super) height: u32,
}

/// The vertical field of view, in degrees, from the top edge of the image to
/// the bottom edge, of an NFF `angle` (degrees, in (0, 180)) that spans the
/// centres of the first and last of `rows` pixel rows.
///
/// The centre of row 0 is half a pixel inside the edge, at
/// `(rows - 1) / rows` of the half-height, so
/// `tan(fov / 2) = tan(angle / 2) · rows / (rows - 1)`. With one row there
/// is nothing to span, and the angle is taken edge to edge.
pub(super) fn edge_to_edge_fov(angle: f64, rows: u32) -> f64 {
    if rows <= 1 {
        return angle;
    }
    let rows = f64::from(rows);
    let half = (0.5 * angle).to_radians().tan() * rows / (rows - 1.0);
    2.0 * half.atan().to_degrees()
}

/// Reads the `v` block; `at` is the span of the `v` keyword.
pub(super) fn read_view(r: &mut Reader<'_>, at: Range<usize>) -> Parsed<View> {
    let (from, from_span) = line(r, "from")?;
    let (look_at, at_span) = line(r, "at")?;
    let (up, up_span) = line(r, "up")?;
    r.word("angle")?;
    let angle_start = r.next_start();
    let angle = r.number("the view's `angle`")?;
    let angle_span = r.since(angle_start);
    r.word("hither")?;
    let hither_start = r.next_start();
    let hither = r.number("the view's `hither`")?;
    if hither < 0.0 {
        let span = r.since(hither_start);
        return Err(r.error(
            span,
            format!("the view's `hither` must not be negative, got {hither}"),
        ));
    }
    r.word("resolution")?;
    let resolution_start = r.next_start();
    let width = side(r, "width")?;
    let height = side(r, "height")?;
    if let Err(error) = check_image_size(width, height) {
        let span = r.since(resolution_start);
        return Err(r.error(span, format!("the view's resolution: {error}")));
    }
    if !(angle > 0.0 && angle < 180.0) {
        return Err(r.error(
            angle_span,
            format!("the view's `angle` must be between 0 and 180 degrees, got {angle}"),
        ));
    }
    let fov = edge_to_edge_fov(angle, height);
    let camera = Camera::new(from, look_at, up, fov).map_err(|error| {
        let (span, message) = match error {
            CameraError::NoViewDirection => {
                (at_span, "the view's `from` and `at` are the same point")
            }
            CameraError::BadUp => (
                up_span,
                "the view's `up` is zero or parallel to the view direction",
            ),
            CameraError::OutOfRange { what: "eye", .. } => {
                (from_span, "the view's `from` is out of range")
            }
            CameraError::OutOfRange { .. } => (at_span, "the view's `at` is out of range"),
            CameraError::BadFov(_) | CameraError::NotFinite | CameraError::ModelOutOfRange(_) => (
                at,
                "the view's `angle` is too close to 180 degrees for this resolution",
            ),
        };
        r.error(span, message)
    })?;
    Ok(View {
        camera,
        width,
        height,
    })
}

/// One side of the view's `resolution`, from 1 to [`MAX_SIDE`] pixels.
fn side(r: &mut Reader<'_>, name: &str) -> Parsed<u32> {
    Ok(
        r.count(&format!("the view's resolution ({name})"), 1, MAX_SIDE)?
            .0,
    )
}

/// A line `name X Y Z` of the view: the vector and the span of its
/// numbers.
fn line(r: &mut Reader<'_>, name: &str) -> Parsed<(Vec3, Range<usize>)> {
    r.word(name)?;
    let start = r.next_start();
    let value = r.vec3(&format!("the view's `{name}`"))?;
    Ok((value, r.since(start)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ray_through_the_first_row_centre_is_half_the_angle_off_the_view() {
        for (angle, width, height) in [(45.0, 512, 512), (25.0, 256, 256), (60.0, 7, 3)] {
            let fov = edge_to_edge_fov(angle, height);
            let camera = Camera::new(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Z, fov).unwrap();
            let forward = (Vec3::ZERO - Vec3::new(1.0, 2.0, 3.0)).normalize();
            // The middle of the image horizontally, the centre of row 0.
            let ray = camera.ray(width, height, f64::from(width) / 2.0, 0.5);
            let off = ray.dir.dot(forward).clamp(-1.0, 1.0).acos().to_degrees();
            assert!((off - angle / 2.0).abs() < 1e-12, "{angle} {height}: {off}");
            // And the last row's centre is as far the other way.
            let last = camera.ray(
                width,
                height,
                f64::from(width) / 2.0,
                f64::from(height) - 0.5,
            );
            let off = last.dir.dot(forward).clamp(-1.0, 1.0).acos().to_degrees();
            assert!((off - angle / 2.0).abs() < 1e-12, "{angle} {height}: {off}");
        }
    }

    #[test]
    fn on_a_square_image_the_columns_span_the_angle_too() {
        let camera =
            Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, edge_to_edge_fov(40.0, 64)).unwrap();
        let left = camera.ray(64, 64, 0.5, 32.0).dir;
        let right = camera.ray(64, 64, 63.5, 32.0).dir;
        let span = left.dot(right).acos().to_degrees();
        assert!((span - 40.0).abs() < 1e-12, "{span}");
    }

    #[test]
    fn the_field_of_view_widens_by_half_a_pixel_each_side() {
        assert!((edge_to_edge_fov(90.0, 2) - 2.0 * 2f64.atan().to_degrees()).abs() < 1e-12);
        assert_eq!(edge_to_edge_fov(45.0, 1), 45.0);
        assert!(edge_to_edge_fov(179.9, 2) < 180.0);
    }
}
