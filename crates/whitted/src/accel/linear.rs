//! Brute force: every primitive tested against every ray. The reference that
//! every faster structure is checked against.

use crate::math::{Aabb, Ray};

/// Tests every primitive, in index order.
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

    /// Finds the closest hit: `hit(i, t_max)` intersects primitive `i` and
    /// returns the parameter of a hit closer than `t_max`, if any. Returns
    /// the closest parameter found.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        mut hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        let mut closest = None;
        let mut t_max = ray.t_max;
        for (i, b) in self.bounds.iter().enumerate() {
            let mut clipped = *ray;
            clipped.t_max = t_max;
            if b.intersect_ray(&clipped).is_none() {
                continue;
            }
            if let Some(t) = hit(i as u32, t_max) {
                t_max = t;
                closest = Some(t);
            }
        }
        closest
    }

    /// True when `occludes(i)` holds for some primitive `i` whose box the ray
    /// meets; stops at the first.
    #[inline]
    pub fn occluded(&self, ray: &Ray, mut occludes: impl FnMut(u32) -> bool) -> bool {
        self.bounds
            .iter()
            .enumerate()
            .any(|(i, b)| b.intersect_ray(ray).is_some() && occludes(i as u32))
    }
}
