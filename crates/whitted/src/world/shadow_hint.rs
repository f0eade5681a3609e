//! The shadow cache (POV-Ray's idea): a shadow ray towards a light is
//! likely blocked by what blocked the previous one towards the same light,
//! so that entry is tested first, and the walk runs only when it does not
//! block. The answer is the any-hit query's own: the hint's test is the one
//! the walk would run on that entry, and a hint is only ever a guess to try
//! (a wrong or stale one costs one test).

use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::{Backend, QueryContext};
use crate::math::Ray;
use crate::world::World;
use crate::world::entry::{EntryKind, Query};
use crate::world::walk::AnyInLeaves;

/// The entry that blocked the last shadow ray of one thread towards one
/// light, if it was one the hinted query can test alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowHint(pub(super) u32);

impl ShadowHint {
    /// No entry to try first.
    pub const NONE: Self = Self(u32::MAX);
}

impl Default for ShadowHint {
    fn default() -> Self {
        Self::NONE
    }
}

impl World<'_> {
    /// Whether the entry `hint` names lies in the query's ray interval,
    /// with the test the any-hit walk runs on it; false for no entry, or
    /// for one that cannot be tested alone (an instance).
    #[inline]
    pub(super) fn hint_blocks(&self, hint: ShadowHint, query: &Query) -> bool {
        let Some(e) = self.entries.get(hint.0 as usize) else {
            return false;
        };
        match e.occlusion_in_place(query) {
            Ok(blocks) => blocks,
            Err(rest) => {
                matches!(
                    e.kind,
                    EntryKind::Primitive | EntryKind::Polygon | EntryKind::Axial
                ) && self.rest_occludes(e.number, query, rest)
            }
        }
    }

    /// [`World::occluded`], trying `hint`'s entry first and leaving in it
    /// the entry that blocked `ray`. Worlds with instances take the plain
    /// query (their hint stays empty).
    pub fn occluded_hinted(&self, ray: &Ray, hint: &mut ShadowHint) -> bool {
        if self.instance_count != 0 {
            *hint = ShadowHint::NONE;
            return self.occluded(ray);
        }
        /// The query as a kernel's task.
        struct Hinted<'q, 'a> {
            world: &'q World<'a>,
            ray: &'q Ray,
            hint: &'q mut ShadowHint,
        }
        impl KernelTask for Hinted<'_, '_> {
            type Output = bool;
            #[inline(always)]
            fn run<K: Kernel>(self) -> bool {
                self.world.occluded_hinted_with::<K>(self.ray, self.hint)
            }
        }
        let backend = Backend::current();
        kernel::run(
            backend,
            Hinted {
                world: self,
                ray,
                hint,
            },
        )
    }

    /// [`World::occluded_hinted`] with kernel `K`.
    #[inline(always)]
    fn occluded_hinted_with<K: Kernel>(&self, ray: &Ray, hint: &mut ShadowHint) -> bool {
        let query = Query::new(ray, self.has_triangles);
        if self.hint_blocks(*hint, &query) {
            return true;
        }
        *hint = ShadowHint::NONE;
        if self
            .unbounded
            .iter()
            .any(|e| self.shape_occludes(e.number, &query))
        {
            return true;
        }
        let mut ctx = QueryContext::default();
        let mut inner = ctx.fresh();
        let leaves = AnyInLeaves::<false> {
            world: self,
            definitions: &[],
            query: &query,
            inner: &mut inner,
            blocker: &mut hint.0,
        };
        self.accel.any_with::<K>(ray, &mut ctx, leaves)
    }
}
