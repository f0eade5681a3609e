//! Ending on a signal: on any signal that ends a process by default and
//! comes from outside it (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1,
//! SIGUSR2, SIGALRM, SIGXCPU, SIGVTALRM, SIGPROF, and on Linux SIGIO,
//! SIGPWR and SIGSTKFLT) the partial files of images being encoded are
//! removed and the process exits with 128 + the signal's number (130 for
//! SIGINT, 143 for SIGTERM), as a shell reports a process killed by it.
//! A signal that was ignored when the command started (SIGHUP under
//! `nohup`, SIGINT for a background job of a script) stays ignored.
//!
//! SIGXFSZ (a file grown past `ulimit -f`) is ignored, so that the write
//! fails with "File too large" and the command says so and removes its
//! partial file, rather than being killed with no word. The faults
//! (SIGSEGV, SIGBUS, SIGFPE, SIGILL), SIGABRT and SIGKILL cannot be
//! handled this way.

use libc::c_int;
use signal_hook::iterator::Signals;

/// The signals handled: see the module's doc.
const ENDING: &[c_int] = &[
    libc::SIGINT,
    libc::SIGTERM,
    libc::SIGHUP,
    libc::SIGQUIT,
    libc::SIGUSR1,
    libc::SIGUSR2,
    libc::SIGALRM,
    libc::SIGXCPU,
    libc::SIGVTALRM,
    libc::SIGPROF,
    #[cfg(target_os = "linux")]
    libc::SIGIO,
    #[cfg(target_os = "linux")]
    libc::SIGPWR,
    #[cfg(target_os = "linux")]
    libc::SIGSTKFLT,
];

/// Starts the thread that waits for the signals and ends the process
/// cleanly when one comes, and ignores SIGXFSZ.
pub fn remove_partial_files_on_signals() -> Result<(), String> {
    // SAFETY: setting a signal's disposition to "ignore" runs no code of
    // ours in a handler.
    if unsafe { libc::signal(libc::SIGXFSZ, libc::SIG_IGN) } == libc::SIG_ERR {
        return Err("cannot ignore SIGXFSZ".to_string());
    }
    let wanted = ENDING.iter().copied().filter(|&s| !is_ignored(s));
    let mut signals =
        Signals::new(wanted).map_err(|e| format!("cannot set up the signal handlers: {e}"))?;
    std::thread::Builder::new()
        .name("signals".to_string())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                // Held while exiting: no partial file can appear meanwhile.
                let _removed = whitted::image::remove_partial_files();
                std::process::exit(128 + signal);
            }
        })
        .map(drop)
        .map_err(|e| format!("cannot start the signal thread: {e}"))
}

/// Whether `signal` is ignored now (as inherited from the parent).
fn is_ignored(signal: libc::c_int) -> bool {
    // SAFETY: a null new action only reads the current one into `old`,
    // which is plain data.
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        libc::sigaction(signal, std::ptr::null(), &mut old) == 0
            && old.sa_sigaction == libc::SIG_IGN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_ignored_signal_is_seen_as_such() {
        // SIGURG is not one the command handles, so the test may change it.
        assert!(!is_ignored(libc::SIGURG));
        // SAFETY: setting a signal to be ignored and back to its default.
        unsafe { libc::signal(libc::SIGURG, libc::SIG_IGN) };
        assert!(is_ignored(libc::SIGURG));
        unsafe { libc::signal(libc::SIGURG, libc::SIG_DFL) };
    }
}
