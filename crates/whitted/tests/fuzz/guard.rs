//! What a panic cannot report: an allocation far larger than any input
//! justifies, and a case that never ends. Both end the process, so before
//! that they print which case was running and how to replay it.
//!
//! Each fuzz target owns one slot saying which case it is running and since
//! when; the capped allocator and the watchdog thread read the slots.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::Once;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Largest single allocation a fuzz case may make. Inputs are at most
/// [`super::mutate::MAX_INPUT`] bytes and renders 8×8 pixels, so anything
/// near this size was sized from a number in the input, not from its
/// length.
pub const MAX_ALLOCATION: usize = 256 << 20;

/// The system allocator, refusing (returning null for) any single
/// allocation over [`MAX_ALLOCATION`]. Code that asks with `try_reserve`
/// gets an error back; anything else aborts, after the running cases are
/// printed.
pub struct CappedAllocator;

// SAFETY: every call is forwarded to `System` unchanged, except that
// oversized requests return null, which `GlobalAlloc` allows.
unsafe impl GlobalAlloc for CappedAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if refused(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if refused(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if refused(new_size) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// True (after saying so) when `size` is over the cap.
fn refused(size: usize) -> bool {
    if size <= MAX_ALLOCATION {
        return false;
    }
    // Writing numbers to the unbuffered stderr does not allocate.
    let _ = writeln!(
        std::io::stderr(),
        "fuzz: refused an allocation of {size} bytes (the cap is {MAX_ALLOCATION})"
    );
    print_running();
    true
}

/// How many targets can run at once (one slot each).
pub const SLOTS: usize = 8;

/// The case a target is running: its seed and when it started, in
/// milliseconds since [`epoch`] plus one (0 when idle).
struct Slot {
    name: AtomicU64,
    seed: AtomicU64,
    started: AtomicU64,
}

static RUNNING: [Slot; SLOTS] = [const {
    Slot {
        name: AtomicU64::new(0),
        seed: AtomicU64::new(0),
        started: AtomicU64::new(0),
    }
}; SLOTS];

/// The instant all start times count from.
fn epoch() -> Instant {
    static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
}

/// Packs a target's name (at most 8 bytes) into a number, so that slots
/// need no allocation to read.
fn pack(name: &str) -> u64 {
    let mut bytes = [0u8; 8];
    for (to, from) in bytes.iter_mut().zip(name.bytes()) {
        *to = from;
    }
    u64::from_le_bytes(bytes)
}

/// Prints every running case with the command that replays it.
fn print_running() {
    let mut err = std::io::stderr();
    for slot in &RUNNING {
        if slot.started.load(Ordering::Acquire) == 0 {
            continue;
        }
        let name = slot.name.load(Ordering::Relaxed).to_le_bytes();
        let length = name.iter().position(|&b| b == 0).unwrap_or(8);
        let name = std::str::from_utf8(&name[..length]).unwrap_or("?");
        let seed = slot.seed.load(Ordering::Relaxed);
        let _ = writeln!(
            err,
            "fuzz: running {name} case {seed:#018x}; replay it with \
             WHITTED_FUZZ_REPLAY={name}:{seed:#018x}"
        );
    }
}

/// Marks the case `seed` of target `name` (slot `slot`) as running.
pub fn start(slot: usize, name: &str, seed: u64) {
    watch();
    let slot = &RUNNING[slot];
    slot.name.store(pack(name), Ordering::Relaxed);
    slot.seed.store(seed, Ordering::Relaxed);
    let now = epoch().elapsed().as_millis() as u64 + 1;
    slot.started.store(now, Ordering::Release);
}

/// Marks the target in `slot` as idle.
pub fn finish(slot: usize) {
    RUNNING[slot].started.store(0, Ordering::Release);
}

/// The longest one case may run before the process is stopped:
/// `WHITTED_FUZZ_HANG_SECONDS`, 60 by default (a debug build under
/// valgrind or on a loaded machine is slow; a hang is forever).
fn hang_limit() -> Duration {
    let seconds = std::env::var("WHITTED_FUZZ_HANG_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    Duration::from_secs(seconds)
}

/// Starts, once, the thread that stops the process when a case hangs.
fn watch() {
    static WATCHDOG: Once = Once::new();
    WATCHDOG.call_once(|| {
        let limit = hang_limit().as_millis() as u64;
        std::thread::spawn(move || {
            loop {
                std::thread::sleep(Duration::from_millis(200));
                let now = epoch().elapsed().as_millis() as u64 + 1;
                let hung = RUNNING.iter().any(|slot| {
                    let started = slot.started.load(Ordering::Acquire);
                    started != 0 && now.saturating_sub(started) > limit
                });
                if hung {
                    eprintln!("fuzz: a case ran for over {limit} ms: a hang");
                    print_running();
                    std::process::abort();
                }
            }
        });
    });
}
