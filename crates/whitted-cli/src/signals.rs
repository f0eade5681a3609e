//! Ending on a signal: on SIGINT, SIGTERM or SIGHUP the partial files of
//! images being encoded are removed and the process exits with 128 + the
//! signal's number (130, 143, 129), as a shell reports a process killed by
//! it.

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Starts the thread that waits for the signals and ends the process
/// cleanly when one comes.
pub fn remove_partial_files_on_signals() -> Result<(), String> {
    let mut signals = Signals::new([SIGINT, SIGTERM, SIGHUP])
        .map_err(|e| format!("cannot set up the signal handlers: {e}"))?;
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
