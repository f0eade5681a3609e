//! The shading frame at a surface point: an orthonormal tangent, bitangent
//! and normal, oriented by the texture coordinates, in which tangent-space
//! normal maps are written.
//!
//! The tangent is `dpdu` made perpendicular to the shading normal (Gram-
//! Schmidt), so it points where `u` grows; the bitangent is `normal ×
//! tangent` or its opposite, whichever lies on the side where `v` grows. A
//! map's +x is thus the image's right and its +y the image's up, whatever
//! the handedness of the (u, v) layout (mirrored texture coordinates on a
//! mesh, the bottom cap of a cylinder, a transform with a mirror).

use crate::math::Vec3;

/// An orthonormal frame around a shading normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentFrame {
    /// Unit vector along which `u` grows.
    pub tangent: Vec3,
    /// Unit vector along which `v` grows (as far as it can while
    /// perpendicular to the other two).
    pub bitangent: Vec3,
    /// The unit shading normal.
    pub normal: Vec3,
}

impl TangentFrame {
    /// The frame around the unit `normal` oriented by the surface's
    /// derivatives `dpdu` and `dpdv` (any lengths).
    ///
    /// Where `dpdu` vanishes or is parallel to the normal (the pole of a
    /// sphere), the bitangent follows `dpdv` and the frame is right-handed;
    /// where both do, the frame is an arbitrary right-handed one around the
    /// normal.
    pub fn new(normal: Vec3, dpdu: Vec3, dpdv: Vec3) -> Self {
        let in_plane = |v: Vec3| (v - normal * normal.dot(v)).try_normalize();
        let (tangent, bitangent) = match (in_plane(dpdu), in_plane(dpdv)) {
            (Some(tangent), _) => {
                let bitangent = normal.cross(tangent);
                if bitangent.dot(dpdv) < 0.0 {
                    (tangent, -bitangent)
                } else {
                    (tangent, bitangent)
                }
            }
            (None, Some(bitangent)) => (bitangent.cross(normal), bitangent),
            (None, None) => normal.any_orthonormal_pair(),
        };
        Self {
            tangent,
            bitangent,
            normal,
        }
    }

    /// The world direction of a vector given in the frame's coordinates
    /// (x along the tangent, y along the bitangent, z along the normal).
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.tangent + v.y * self.bitangent + v.z * self.normal
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    fn assert_orthonormal(f: &TangentFrame) {
        for (a, b) in [
            (f.tangent, f.bitangent),
            (f.bitangent, f.normal),
            (f.normal, f.tangent),
        ] {
            assert!(a.dot(b).abs() < 1e-12, "{f:?}");
        }
        for v in [f.tangent, f.bitangent, f.normal] {
            assert!((v.length() - 1.0).abs() < 1e-12, "{f:?}");
        }
    }

    #[test]
    fn random_tangents_give_an_orthonormal_frame_following_u_and_v() {
        let mut rng = Rng::new(3);
        for _ in 0..1000 {
            let normal = rng.unit_vector();
            let dpdu = rng.unit_vector() * rng.range(0.01, 10.0);
            let dpdv = rng.unit_vector() * rng.range(0.01, 10.0);
            let f = TangentFrame::new(normal, dpdu, dpdv);
            assert_orthonormal(&f);
            if dpdu.cross(normal).length() > 1e-3 * dpdu.length() {
                assert!(f.tangent.dot(dpdu) > 0.0);
            }
            assert!(f.bitangent.dot(dpdv) >= 0.0);
        }
    }

    #[test]
    fn mirrored_texture_coordinates_flip_the_bitangent() {
        let right = TangentFrame::new(Vec3::Z, Vec3::X, Vec3::Y);
        assert_eq!((right.tangent, right.bitangent), (Vec3::X, Vec3::Y));
        let mirrored = TangentFrame::new(Vec3::Z, Vec3::X, -Vec3::Y);
        assert_eq!((mirrored.tangent, mirrored.bitangent), (Vec3::X, -Vec3::Y));
        assert_eq!(mirrored.to_world(Vec3::new(0.0, 1.0, 0.0)), -Vec3::Y);
    }

    #[test]
    fn vanishing_tangents_fall_back_to_dpdv_then_to_any_frame() {
        let pole = TangentFrame::new(Vec3::Z, Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0));
        assert_eq!((pole.tangent, pole.bitangent), (Vec3::X, Vec3::Y));
        let along_normal = TangentFrame::new(Vec3::Z, Vec3::Z, Vec3::ZERO);
        assert_orthonormal(&along_normal);
        assert!((along_normal.tangent.cross(along_normal.bitangent) - Vec3::Z).length() < 1e-15);
        let nothing = TangentFrame::new(-Vec3::Y, Vec3::ZERO, Vec3::ZERO);
        assert_orthonormal(&nothing);
    }
}
