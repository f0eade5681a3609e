//! Rays that travel together, as one query: a packet of up to
//! [`PACKET_SIZE`] rays stored structure-of-arrays (each coordinate of all
//! rays side by side, as SIMD lanes want them), with a mask of the lanes in
//! use, and the answers per lane under the same mask.
//!
//! [`crate::world::World::intersect_packet`] and
//! [`crate::world::World::occluded_packet`] answer a packet today by
//! tracing its rays one at a time, so they give exactly the single-ray
//! answers; a walk that tests the packet against a node at once can come
//! behind the same calls.

use crate::math::{Ray, Vec3};
use crate::world::Hit;

/// The most rays a packet holds.
pub const PACKET_SIZE: usize = 8;

/// Up to [`PACKET_SIZE`] rays, structure-of-arrays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayPacket {
    /// Origins, per axis then per lane.
    pub origin: [[f64; PACKET_SIZE]; 3],
    /// Directions, per axis then per lane.
    pub dir: [[f64; PACKET_SIZE]; 3],
    /// Start of each lane's interval.
    pub t_min: [f64; PACKET_SIZE],
    /// End of each lane's interval.
    pub t_max: [f64; PACKET_SIZE],
    /// Bit `i` set when lane `i` holds a ray.
    pub active: u32,
}

impl RayPacket {
    /// The packet of `rays` (at most [`PACKET_SIZE`]; the rest are left
    /// out), lane `i` holding `rays[i]`.
    pub fn new(rays: &[Ray]) -> Self {
        let mut packet = Self {
            origin: [[0.0; PACKET_SIZE]; 3],
            dir: [[0.0; PACKET_SIZE]; 3],
            t_min: [0.0; PACKET_SIZE],
            t_max: [0.0; PACKET_SIZE],
            active: 0,
        };
        for (lane, ray) in rays.iter().take(PACKET_SIZE).enumerate() {
            for axis in 0..3 {
                packet.origin[axis][lane] = ray.origin[axis];
                packet.dir[axis][lane] = ray.dir[axis];
            }
            packet.t_min[lane] = ray.t_min;
            packet.t_max[lane] = ray.t_max;
            packet.active |= 1 << lane;
        }
        packet
    }

    /// The ray in `lane`, whether active or not.
    #[inline]
    pub fn ray(&self, lane: usize) -> Ray {
        let at = |v: &[[f64; PACKET_SIZE]; 3]| Vec3::new(v[0][lane], v[1][lane], v[2][lane]);
        let mut ray = Ray::segment(at(&self.origin), at(&self.dir), self.t_max[lane]);
        ray.t_min = self.t_min[lane];
        ray
    }

    /// The active lanes, in order.
    pub fn lanes(&self) -> impl Iterator<Item = usize> + '_ {
        (0..PACKET_SIZE).filter(|&lane| self.active & 1 << lane != 0)
    }

    /// How many lanes are active.
    pub fn len(&self) -> usize {
        self.active.count_ones() as usize
    }

    /// True when no lane is active.
    pub fn is_empty(&self) -> bool {
        self.active == 0
    }
}

/// The closest hits of a packet's rays: lane `i`'s in `hits[i]`, meaningful
/// where bit `i` of `mask` is set (the lane hit something).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacketHits {
    /// Each lane's hit; `None` for a miss or an inactive lane.
    pub hits: [Option<Hit>; PACKET_SIZE],
    /// Bit `i` set when lane `i` hit something.
    pub mask: u32,
}

impl Default for PacketHits {
    fn default() -> Self {
        Self {
            hits: [None; PACKET_SIZE],
            mask: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_packet_gives_back_each_ray_and_masks_the_unused_lanes() {
        let rays = [
            Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::X),
            Ray::segment(Vec3::ZERO, Vec3::Y, 4.0),
            Ray::new(Vec3::splat(-1.0), Vec3::new(0.0, 0.6, 0.8)),
        ];
        let packet = RayPacket::new(&rays);
        assert_eq!(packet.active, 0b111);
        assert_eq!(packet.len(), 3);
        assert_eq!(packet.lanes().collect::<Vec<_>>(), [0, 1, 2]);
        for (lane, ray) in rays.iter().enumerate() {
            assert_eq!(packet.ray(lane), *ray);
        }
        let many = [rays[0]; PACKET_SIZE + 3];
        assert_eq!(RayPacket::new(&many).len(), PACKET_SIZE);
        assert!(RayPacket::new(&[]).is_empty());
    }
}
