//! Ending on a signal: on SIGINT, SIGTERM or SIGHUP the partial files of
//! images being encoded are removed and the process exits with 128 + the
//! signal's number (130, 143, 129), as a shell reports a process killed by
//! it. A signal that was ignored when the command started (SIGHUP under
//! `nohup`, SIGINT for a background job of a script) stays ignored.

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Starts the thread that waits for the signals and ends the process
/// cleanly when one comes.
pub fn remove_partial_files_on_signals() -> Result<(), String> {
    let wanted = [SIGINT, SIGTERM, SIGHUP]
        .into_iter()
        .filter(|&s| !is_ignored(s));
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
        // SIGUSR2 is not one the command handles, so the test may change it.
        assert!(!is_ignored(libc::SIGUSR2));
        // SAFETY: setting a signal to be ignored and back to its default.
        unsafe { libc::signal(libc::SIGUSR2, libc::SIG_IGN) };
        assert!(is_ignored(libc::SIGUSR2));
        unsafe { libc::signal(libc::SIGUSR2, libc::SIG_DFL) };
    }
}
