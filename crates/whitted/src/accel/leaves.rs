//! What a walk does at the leaves it reaches: the caller's policy, as a
//! type. A caller whose leaf test is hot implements these traits with
//! `#[inline(always)]` methods, so that the test is compiled into the walk
//! under the kernel's target features (a closure is inlined or not as the
//! compiler judges); any closure of the right shape is one too. The
//! methods are told the walk's kernel, whose leaf tests they may use.

use std::ops::Range;

use super::kernel::Kernel;

/// The leaves of a closest-hit walk.
pub(crate) trait ClosestLeaves {
    /// The closest hit among the leaf's primitives `range` (positions in
    /// the structure's leaf order) nearer than `t_max`, if any.
    fn closest<K: Kernel>(&mut self, range: Range<u32>, t_max: f64) -> Option<f64>;
}

impl<F: FnMut(Range<u32>, f64) -> Option<f64>> ClosestLeaves for F {
    #[inline(always)]
    fn closest<K: Kernel>(&mut self, range: Range<u32>, t_max: f64) -> Option<f64> {
        self(range, t_max)
    }
}

/// The leaves of an any-hit walk.
pub(crate) trait AnyLeaves {
    /// Whether any of the leaf's primitives `range` lies in the ray's
    /// interval.
    fn occludes<K: Kernel>(&mut self, range: Range<u32>) -> bool;
}

impl<F: FnMut(Range<u32>) -> bool> AnyLeaves for F {
    #[inline(always)]
    fn occludes<K: Kernel>(&mut self, range: Range<u32>) -> bool {
        self(range)
    }
}
