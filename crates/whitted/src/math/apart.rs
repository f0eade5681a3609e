//! Reading a vector's coordinates with one load each, for the per-ray
//! set-ups that run right after the ray was written.
//!
//! A ray is mostly written just before it is traced. Where the compiler
//! merged the reads of two or three coordinates into one wide load, that
//! load could not take its bytes from the narrower stores still waiting to
//! be written (store forwarding fails) and waited for them (the BVH walk's
//! set-up and the triangles' shear on small meshes: docs/performance-log.md).
//! A load of one coordinate is forwarded from the store that wrote it,
//! whatever its width.

use super::Vec3;

/// The coordinates of `v`, read with one load each.
#[inline(always)]
pub fn coordinates_apart(v: &Vec3) -> [f64; 3] {
    // SAFETY: each pointer is to an initialised `f64`. The reads are
    // volatile only so that they are not merged into one wide load.
    unsafe {
        [
            std::ptr::read_volatile(&v.x),
            std::ptr::read_volatile(&v.y),
            std::ptr::read_volatile(&v.z),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_coordinates_in_order() {
        let v = Vec3::new(1.5, -0.0, f64::INFINITY);
        let [x, y, z] = coordinates_apart(&v);
        assert_eq!(
            [x.to_bits(), y.to_bits(), z.to_bits()],
            v.to_array().map(f64::to_bits)
        );
    }
}
