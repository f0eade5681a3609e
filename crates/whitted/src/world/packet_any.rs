//! Shadow rays that travel together, as one query: up to [`PACKET_SIZE`]
//! rays (shadow rays from neighbouring hits towards one light, as
//! `whitted bench --packets` walks them; the renderer's stay single) whose
//! any-hit answers are found by one walk of the BVH
//! ([`Bvh::occluded_packet_by_leaf`]), each the answer its own walk gives.
//!
//! Any-hit answers do not depend on the order in which leaves are met, so
//! every entry kind a packet may walk (see `packet`) answers as alone; a
//! world or a packet that cannot be walked together is answered one ray at
//! a time.

use crate::accel::{Accelerator, Bvh, QueryContext};
use crate::math::Ray;
use crate::shape::WideLanes;

use super::World;
use super::entry::{Query, Rest, leaf_occludes};
use super::packet::PACKET_SIZE;

impl World<'_> {
    /// Which of `rays` (at most [`PACKET_SIZE`]) meet something in their
    /// interval: bit `i` is set when `rays[i]` is occluded, as
    /// [`Self::occluded_with`] answers for it alone. Walked together where
    /// the world and the rays allow it.
    ///
    /// # Panics
    ///
    /// When there are more than [`PACKET_SIZE`] rays.
    pub fn occluded_packet(&self, rays: &[Ray], ctx: &mut QueryContext) -> u32 {
        assert!(rays.len() <= PACKET_SIZE, "{} rays in a packet", rays.len());
        let together = match &self.accel {
            Accelerator::Bvh(bvh) if self.walks_packets_with(ctx.backend) && !rays.is_empty() => {
                self.occluded_together(bvh, rays, ctx)
            }
            _ => None,
        };
        together.unwrap_or_else(|| {
            rays.iter()
                .enumerate()
                .filter(|(_, ray)| self.occluded_with(ray, ctx))
                .fold(0, |mask, (lane, _)| mask | 1 << lane)
        })
    }

    /// The packet walk of [`Self::occluded_packet`] over `bvh`, this
    /// world's structure, or `None` when the packet cannot be walked
    /// together.
    fn occluded_together(&self, bvh: &Bvh, rays: &[Ray], ctx: &mut QueryContext) -> Option<u32> {
        let all = (1u32 << rays.len()) - 1;
        // A lane's query (its triangle shear) is made when the lane first
        // reaches an entry.
        let mut queries: [Option<Query>; PACKET_SIZE] = [None; PACKET_SIZE];
        let mut inner = QueryContext::new(ctx.coherence);
        let mut occluded = 0;
        if !self.unbounded.is_empty() {
            for (lane, ray) in rays.iter().enumerate() {
                let query = queries[lane].insert(Query::new(ray, self.has_triangles));
                if self.unbounded.iter().any(|e| {
                    self.other_occludes(&self.definitions, e, (query, Rest::Test), &mut inner)
                }) {
                    occluded |= 1 << lane;
                }
            }
        }
        let walked = bvh.occluded_packet_by_leaf(
            rays,
            (all & !occluded, ctx.backend),
            &mut ctx.counters,
            |lanes, range| {
                let mut found = 0;
                let mut bits = lanes;
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let query = queries[lane]
                        .get_or_insert_with(|| Query::new(&rays[lane], self.has_triangles));
                    let meets = leaf_occludes::<WideLanes>(
                        &self.entries,
                        range.clone(),
                        query,
                        |e, rest| self.rest_occludes(e.number, query, rest),
                    );
                    if meets.is_some() {
                        found |= 1 << lane;
                    }
                }
                found
            },
        );
        // A packet not walked together is answered ray by ray, planes and
        // all, and counted then.
        let walked = walked?;
        ctx.counters += inner.counters;
        Some(occluded | walked)
    }
}

#[cfg(test)]
mod tests {
    use super::super::packet::tests::{closed_form_scene, has_avx, triangles_only};
    use super::*;
    use crate::accel::{AccelKind, Backend, Isa};
    use crate::math::Vec3;
    use crate::math::random::Rng;
    use crate::world::Objects;

    /// Packets of up to eight shadow rays from points scattered over a
    /// patch of side `spread` in the scene towards one light outside it,
    /// each ending at the light.
    fn shadow_packets(rng: &mut Rng, count: usize, spread: f64) -> Vec<Vec<Ray>> {
        (0..count)
            .map(|_| {
                let centre = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
                let light = 12.0 * rng.unit_vector();
                let lanes = 1 + rng.below(PACKET_SIZE as u32) as usize;
                (0..lanes)
                    .map(|_| {
                        let from = centre + rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                        let to = light - from;
                        Ray::segment(from, to.normalize(), to.length())
                    })
                    .collect()
            })
            .collect()
    }

    /// Every lane of each packet is found occluded as its single walk and
    /// brute force find it; returns how many packets were walked together
    /// and how many lanes were occluded and clear.
    fn assert_shadow_packets_agree(objects: &Objects, packets: &[Vec<Ray>]) -> [usize; 3] {
        let world = World::new(objects);
        let brute = World::build(objects, AccelKind::Linear);
        let mut counts = [0; 3];
        for rays in packets {
            let mut ctx = QueryContext::default();
            let occluded = world.occluded_packet(rays, &mut ctx);
            for backend in Isa::ALL.into_iter().filter_map(Backend::new) {
                let mut narrowed = QueryContext {
                    backend,
                    ..QueryContext::default()
                };
                assert_eq!(world.occluded_packet(rays, &mut narrowed), occluded);
            }
            if let Accelerator::Bvh(bvh) = &world.accel {
                counts[0] += usize::from(world.occluded_together(bvh, rays, &mut ctx).is_some());
            }
            assert_eq!(occluded >> rays.len(), 0);
            for (lane, ray) in rays.iter().enumerate() {
                let single = world.occluded(ray);
                assert_eq!(occluded >> lane & 1 == 1, single, "lane {lane} of {rays:?}");
                assert_eq!(single, brute.occluded(ray));
                counts[if single { 1 } else { 2 }] += 1;
            }
        }
        counts
    }

    #[test]
    fn shadow_packets_are_occluded_as_their_single_walks() {
        let mut rng = Rng::new(41);
        for objects in [
            closed_form_scene(&mut rng, false),
            closed_form_scene(&mut rng, true),
            triangles_only(&mut rng, 24),
        ] {
            assert_eq!(World::new(&objects).walks_packets(), has_avx());
            let mut packets = shadow_packets(&mut rng, 300, 0.05);
            packets.extend(shadow_packets(&mut rng, 300, 1.0));
            let [together, occluded, clear] = assert_shadow_packets_agree(&objects, &packets);
            if has_avx() {
                assert!(together > 400, "{together}");
            }
            assert!(occluded > 300 && clear > 300, "{occluded} {clear}");
        }
    }
}
