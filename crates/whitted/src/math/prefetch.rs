//! Asking the processor to start loading memory that a later step reads,
//! so that the wait for a cache miss overlaps other work.

/// Starts loading the cache line that holds the start of `value` into
/// every cache level. A hint only: it reads nothing and cannot fault.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: a prefetch reads no memory; `value` is a valid reference.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((value as *const T).cast()) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
