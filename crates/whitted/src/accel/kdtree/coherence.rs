//! Whether the rays a thread has been tracing are coherent, to pick how a
//! walk starts (`traverse.rs`).
//!
//! The walk branches at every node on the ray's direction along the
//! node's axis. Rays that go the same way one after the other (camera
//! rays, shadow rays towards one light) take those branches the same way,
//! and the branch predictor learns them; rays that change direction from
//! one to the next (diffuse bounces) do not, and the walk waits on
//! mispredicted branches. The descent to the origin's leaf branches on the
//! origin's side of each plane instead, which neighbouring origins share,
//! but it does more arithmetic a step, which coherent rays pay for.
//!
//! So each thread keeps a running share of its rays whose direction lies
//! in another octant than the ray before's: about 0 for coherent streams,
//! three quarters for rays spread over a hemisphere. Only the speed
//! depends on it: both starts visit every cell the ray passes.

use std::cell::Cell;

/// The share of changes is kept in fixed point: 1 is this much.
const ONE: u32 = 1 << 10;

/// Each ray moves the share this fraction (1/2^k) of the way towards 0 or
/// 1: about the last 16 rays count.
const DECAY_SHIFT: u32 = 4;

/// Above this share of octant changes the rays count as incoherent.
const INCOHERENT_ABOVE: u32 = ONE / 3;

thread_local! {
    /// The last ray's octant in bits 0-2, the share of changes above.
    static HISTORY: Cell<u32> = const { Cell::new(0) };
}

#[cfg(test)]
thread_local! {
    /// The answer [`incoherent`] gives on this thread, if pinned.
    static PINNED: Cell<Option<bool>> = const { Cell::new(None) };
}

/// Records a ray going into `octant` (one bit per axis, set where the
/// direction is negative) and says whether this thread's recent rays,
/// this one included, are incoherent.
#[inline(always)]
pub(super) fn incoherent(octant: u32) -> bool {
    let history = HISTORY.get();
    let share = history >> 3;
    let changed = u32::from(history & 7 != octant);
    let share = share - (share >> DECAY_SHIFT) + (changed << (10 - DECAY_SHIFT));
    HISTORY.set((share << 3) | octant);
    #[cfg(test)]
    if let Some(pinned) = PINNED.get() {
        return pinned;
    }
    share > INCOHERENT_ABOVE
}

/// Makes [`incoherent`] answer `answer` on this thread (`None`: measure
/// again), so tests can run both starts of the walk.
#[cfg(test)]
pub(super) fn pin(answer: Option<bool>) {
    PINNED.set(answer);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// How many of `octants`, fed in order, count as incoherent.
    fn incoherent_count(octants: impl Iterator<Item = u32>) -> usize {
        HISTORY.set(0);
        octants.filter(|&o| incoherent(o)).count()
    }

    #[test]
    fn rays_in_one_octant_are_coherent() {
        assert_eq!(incoherent_count(std::iter::repeat_n(5, 1000)), 0);
    }

    #[test]
    fn rays_in_random_octants_are_incoherent_after_a_few() {
        let mut rng = Rng::new(3);
        let octants: Vec<u32> = (0..1000).map(|_| rng.below(8)).collect();
        assert!(incoherent_count(octants.iter().copied()) > 950);
    }

    #[test]
    fn rays_changing_octant_now_and_then_stay_coherent() {
        // A change every tenth ray: an image's rows, a second light.
        let octants = (0..1000).map(|i| (i / 10) % 2);
        assert_eq!(incoherent_count(octants), 0);
    }

    #[test]
    fn the_share_forgets_old_rays() {
        let mut rng = Rng::new(4);
        let random = (0..200).map(|_| rng.below(8));
        let steady = std::iter::repeat_n(2, 200);
        let history: Vec<bool> = {
            HISTORY.set(0);
            random.chain(steady).map(incoherent).collect()
        };
        assert!(history[150..200].iter().all(|&x| x));
        assert!(history[300..].iter().all(|&x| !x));
    }

    #[test]
    fn a_pinned_answer_overrides_the_history() {
        pin(Some(true));
        assert_eq!(incoherent_count(std::iter::repeat_n(1, 10)), 10);
        pin(None);
        assert_eq!(incoherent_count(std::iter::repeat_n(1, 10)), 0);
    }
}
