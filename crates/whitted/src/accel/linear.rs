//! Brute force: every primitive tested against every ray. The reference that
//! every faster structure is checked against.

use super::{AccelStats, QueryContext};
use crate::math::{Aabb, Ray};

/// Tests every primitive whose box the ray meets, in index order.
#[derive(Clone, Debug, Default)]
pub struct Linear {
    bounds: Vec<Aabb>,
}

impl Linear {
    /// A structure over primitives `0..bounds.len()` with these boxes.
    pub fn build(bounds: &[Aabb]) -> Self {
        Self {
            bounds: bounds.to_vec(),
        }
    }

    /// How many primitives it holds.
    pub fn len(&self) -> usize {
        self.bounds.len()
    }

    /// True when it holds none.
    pub fn is_empty(&self) -> bool {
        self.bounds.is_empty()
    }

    /// The closest hit (see [`super`]).
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        let counters = &mut ctx.counters;
        let mut closest = None;
        let mut clipped = *ray;
        for (i, b) in self.bounds.iter().enumerate() {
            counters.nodes += 1;
            if b.intersect_ray(&clipped).is_none() {
                continue;
            }
            counters.primitives += 1;
            if let Some(t) = hit(i as u32, clipped.t_max) {
                clipped.t_max = t;
                closest = Some(t);
            }
        }
        closest
    }

    /// Any hit (see [`super`]).
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        let counters = &mut ctx.counters;
        self.bounds.iter().enumerate().any(|(i, b)| {
            counters.nodes += 1;
            if b.intersect_ray(ray).is_none() {
                return false;
            }
            counters.primitives += 1;
            occludes(i as u32)
        })
    }

    /// Checks that it holds exactly these boxes.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        if self.bounds == boxes {
            Ok(())
        } else {
            Err("the stored boxes differ from the primitives' boxes".to_string())
        }
    }

    /// One leaf holding everything.
    pub fn stats(&self) -> AccelStats {
        AccelStats {
            nodes: 1,
            leaves: 1,
            references: self.bounds.len(),
            memory_bytes: std::mem::size_of_val(self.bounds.as_slice()),
            sah_cost: self.bounds.len() as f64,
            max_depth: 0,
        }
    }
}
