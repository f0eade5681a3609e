//! Rays counted by kind. Each integrator traces some of the kinds
//! ([`crate::integrator::Integrator::ray_kinds`]); a summary lists those.

use std::ops::{AddAssign, Index, IndexMut};

/// What a ray was traced for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayKind {
    /// From the camera through a pixel.
    Primary,
    /// Towards a light, to find whether it is seen (one per light per
    /// shaded point, plus one per transmissive surface crossed).
    Shadow,
    /// Mirror-reflected.
    Reflected,
    /// Refracted (or passing straight through a dissolved surface).
    Refracted,
}

impl RayKind {
    /// Every kind, in report order.
    pub const ALL: [RayKind; 4] = [
        RayKind::Primary,
        RayKind::Shadow,
        RayKind::Reflected,
        RayKind::Refracted,
    ];

    /// The name used in summaries.
    pub fn name(&self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Shadow => "shadow",
            RayKind::Reflected => "reflected",
            RayKind::Refracted => "refracted",
        }
    }
}

/// How many rays of each kind were traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts([u64; RayKind::ALL.len()]);

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.0.iter().sum()
    }
}

impl Index<RayKind> for RayCounts {
    type Output = u64;
    #[inline]
    fn index(&self, kind: RayKind) -> &u64 {
        &self.0[kind as usize]
    }
}

impl IndexMut<RayKind> for RayCounts {
    #[inline]
    fn index_mut(&mut self, kind: RayKind) -> &mut u64 {
        &mut self.0[kind as usize]
    }
}

impl AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_add_up_by_kind() {
        let mut a = RayCounts::default();
        a[RayKind::Primary] += 3;
        a[RayKind::Shadow] += 2;
        let mut b = RayCounts::default();
        b[RayKind::Shadow] += 5;
        b[RayKind::Refracted] += 1;
        a += b;
        assert_eq!(a[RayKind::Shadow], 7);
        assert_eq!(a[RayKind::Reflected], 0);
        assert_eq!(a.total(), 11);
    }
}
