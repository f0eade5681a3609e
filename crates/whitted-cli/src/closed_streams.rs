//! Whether standard output was closed when the process started (`>&-`).
//!
//! Before `main` runs, the Rust runtime opens `/dev/null` in place of a
//! closed standard stream, so that a file opened later cannot take its
//! number; writes to it then succeed and results written there are lost
//! without a word. A function the loader calls before the runtime starts
//! (an `.init_array` entry, run before `main` and everything it calls)
//! looks first, and [`stdout_was_closed`] answers from what it saw.

use std::sync::atomic::{AtomicBool, Ordering};

/// What the check before `main` found.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Notes whether descriptor 1 is open; the loader calls it before `main`.
extern "C" fn note_closed_stdout() {
    // SAFETY: F_GETFD only reads the descriptor's flags; it fails with
    // EBADF on a closed descriptor and touches no memory.
    let closed = unsafe { libc::fcntl(libc::STDOUT_FILENO, libc::F_GETFD) } == -1;
    STDOUT_CLOSED.store(closed, Ordering::Relaxed);
}

/// The loader's list of functions to call before `main` (the mechanism
/// C and C++ constructors use).
#[used]
#[cfg_attr(not(target_vendor = "apple"), unsafe(link_section = ".init_array"))]
#[cfg_attr(
    target_vendor = "apple",
    unsafe(link_section = "__DATA,__mod_init_func")
)]
static NOTE_CLOSED_STDOUT: extern "C" fn() = note_closed_stdout;

/// Whether standard output was closed when the process started: what the
/// command writes there would go nowhere.
pub fn stdout_was_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}
