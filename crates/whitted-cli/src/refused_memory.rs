//! Memory the system refuses ends the run as an error, not as an abort.
//!
//! The memory budget keeps what a run asks for within what the process
//! may use, and the largest requests that depend on input (films,
//! textures) are made so that a refusal is an error the caller reports.
//! Any other request the system refuses (a `--max-memory` above
//! `ulimit -v`, or memory taken by other processes) makes the standard
//! library print "memory allocation of N bytes failed" and abort. This
//! module turns that abort into what every other error is: the partial
//! files of images being encoded are removed, a message says what
//! happened and what to do, and the process exits with status 1.
//!
//! The process's allocator ([`Noting`]) is the system's, noting on each
//! thread the size of a request it refuses, forgotten as the thread goes
//! on; a `SIGABRT` handler then tells an abort that follows a refusal from
//! any other. Another abort, or a `SIGABRT` sent from outside,
//! still aborts, once the partial files are removed.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::fmt::Write as _;

use libc::c_int;
use whitted::limits::ByteSize;

thread_local! {
    /// On each thread, the size of a request the system refused and how
    /// many requests were granted since; forgotten once [`FORGOTTEN_AFTER`]
    /// were. The standard library answers a refusal it cannot hand back by
    /// aborting on the thread that asked, after a few small requests of its
    /// own (to print its message), so an abort that finds a note here
    /// follows a refusal; a refusal the caller handled (a fallible
    /// reservation) is forgotten as the thread goes on.
    static REFUSED: Cell<(usize, u32)> = const { Cell::new((0, 0)) };
}

/// Requests granted after a refusal before it is forgotten.
const FORGOTTEN_AFTER: u32 = 64;

/// The system's allocator, noting in [`REFUSED`] whether the thread's last
/// request was refused; it gives the same answers.
pub struct Noting;

/// `pointer`, after noting on this thread `size` when it is null, or
/// counting a granted request towards forgetting a refusal.
#[inline]
fn noted(pointer: *mut u8, size: usize) -> *mut u8 {
    // A thread being torn down no longer has its note: nothing to say then.
    let _ = REFUSED.try_with(|note| {
        let (refused, since) = note.get();
        if pointer.is_null() {
            note.set((size.max(1), 0));
        } else if refused != 0 {
            let since = since + 1;
            note.set(if since > FORGOTTEN_AFTER {
                (0, 0)
            } else {
                (refused, since)
            });
        }
    });
    pointer
}

// SAFETY: every call is passed to `System` unchanged, and its answer
// returned unchanged.
unsafe impl GlobalAlloc for Noting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        noted(unsafe { System.alloc(layout) }, layout.size())
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        noted(unsafe { System.alloc_zeroed(layout) }, layout.size())
    }

    unsafe fn dealloc(&self, pointer: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract is `System`'s.
        unsafe { System.dealloc(pointer, layout) }
    }

    unsafe fn realloc(&self, pointer: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        noted(
            unsafe { System.realloc(pointer, layout, new_size) },
            new_size,
        )
    }
}

/// Installs the `SIGABRT` handler (see the module's doc), for the rest of
/// the process's life.
pub fn end_refusals_as_errors() -> Result<(), String> {
    // SAFETY: the action is plain data, and the handler does only what a
    // handler may (see `on_abort`).
    unsafe {
        let mut action: libc::sigaction = std::mem::zeroed();
        action.sa_sigaction = on_abort as extern "C" fn(c_int) as libc::sighandler_t;
        // Once: an abort raised again after the handler returns is the
        // default one.
        action.sa_flags = libc::SA_RESETHAND;
        libc::sigemptyset(&mut action.sa_mask);
        if libc::sigaction(libc::SIGABRT, &action, std::ptr::null_mut()) != 0 {
            return Err(format!(
                "cannot handle aborts: {}",
                std::io::Error::last_os_error()
            ));
        }
    }
    Ok(())
}

/// The handler of `SIGABRT`. An abort is raised by the thread that
/// aborts, outside the allocator, so that removing the partial files
/// (which neither waits nor allocates) and writing from the stack are
/// safe here.
extern "C" fn on_abort(_signal: c_int) {
    let _ = whitted::image::remove_partial_files_now();
    let refused = REFUSED
        .try_with(Cell::get)
        .map_or(0, |(refused, _)| refused);
    if refused == 0 {
        // Not a refusal (an abort of another kind, or SIGABRT sent from
        // outside): the default action, restored by `SA_RESETHAND`, ends
        // the process when the signal is raised again.
        // SAFETY: raising a signal is what a handler may do.
        unsafe { libc::raise(libc::SIGABRT) };
        return;
    }
    let mut message = StackText::new();
    write_refusal(&mut message, refused);
    // SAFETY: writing bytes of the stack to descriptor 2 and exiting
    // without running anything else are what a handler may do.
    unsafe {
        libc::write(
            libc::STDERR_FILENO,
            message.bytes().as_ptr().cast(),
            message.bytes().len(),
        );
        libc::_exit(1);
    }
}

/// What is said of a refused request of `bytes`, as a line of `out`.
fn write_refusal(out: &mut StackText, bytes: usize) {
    let _ = writeln!(
        out,
        "error: the system refused {} of memory the memory budget allowed (a --max-memory \
         above the process's limit, ulimit -v, or memory taken by others); free memory, \
         raise the limit, or lower --max-memory to what the system gives",
        ByteSize(bytes as u64)
    );
}

/// Text written into a buffer on the stack; what does not fit is cut.
struct StackText {
    buffer: [u8; 512],
    length: usize,
}

impl StackText {
    fn new() -> Self {
        Self {
            buffer: [0; 512],
            length: 0,
        }
    }

    fn bytes(&self) -> &[u8] {
        &self.buffer[..self.length]
    }
}

impl std::fmt::Write for StackText {
    fn write_str(&mut self, text: &str) -> std::fmt::Result {
        let room = self.buffer.len() - self.length;
        let taken = text.len().min(room);
        self.buffer[self.length..self.length + taken].copy_from_slice(&text.as_bytes()[..taken]);
        self.length += taken;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refusal_is_noted_on_its_thread_and_forgotten_as_it_goes_on() {
        std::thread::spawn(|| {
            let granted = std::ptr::NonNull::<u8>::dangling().as_ptr();
            let note = || REFUSED.with(Cell::get).0;
            noted(std::ptr::null_mut(), 1 << 30);
            assert_eq!(note(), 1 << 30);
            assert_eq!(
                std::thread::spawn(|| REFUSED.with(Cell::get).0)
                    .join()
                    .unwrap(),
                0
            );
            // Noted afresh: spawning took requests of this thread's.
            noted(std::ptr::null_mut(), 3 << 30);
            for _ in 0..FORGOTTEN_AFTER {
                noted(granted, 8);
            }
            assert_eq!(note(), 3 << 30, "the abort's own requests keep it");
            noted(granted, 8);
            assert_eq!(note(), 0, "forgotten as the thread goes on");
        })
        .join()
        .unwrap();
    }

    #[test]
    fn text_past_the_buffer_is_cut_not_overflowed() {
        let mut text = StackText::new();
        for _ in 0..100 {
            write!(text, "0123456789").unwrap();
        }
        assert_eq!(text.bytes().len(), 512);
        assert!(text.bytes().starts_with(b"0123456789"));
    }

    #[test]
    fn the_message_names_the_size_and_the_remedies() {
        let mut text = StackText::new();
        write_refusal(&mut text, 3 << 30);
        let text = std::str::from_utf8(text.bytes()).unwrap();
        assert!(
            text.starts_with("error: the system refused 3.0 GiB of memory"),
            "{text}"
        );
        assert!(text.ends_with("to what the system gives\n"), "{text}");
        assert!(text.contains("ulimit -v"), "{text}");
        assert!(text.contains("--max-memory"), "{text}");
    }
}
