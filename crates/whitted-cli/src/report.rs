//! Everything the command prints goes through here, and nothing here
//! panics (`println!` and `eprintln!` panic when the stream fails, and are
//! denied in this crate).
//!
//! - Reports (progress notes, warnings, errors) go to standard error with
//!   [`note!`]. A report that cannot be written (a closed
//!   pipe, a full device) ends the reporting, not the work: nothing more is
//!   tried on standard error, and the exit code is what the work decides.
//! - Results (`bench`'s table or JSON) go to standard output with
//!   [`results`]. Results that cannot be written are an error: the command
//!   says so on standard error if it can and exits with 1, as for any
//!   other failure.

use std::borrow::Cow;
use std::fmt;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use whitted::scene::quotes_cut;

/// Writes a line (`format!` arguments) on standard error, if reports can
/// still be written there.
macro_rules! note {
    ($($arg:tt)*) => {
        $crate::report::note_line(format_args!($($arg)*))
    };
}

pub(crate) use note;

/// A stream for reports that gives up at its first failed write.
pub struct ReportStream {
    failed: AtomicBool,
}

impl ReportStream {
    /// A stream that has not failed.
    pub const fn new() -> Self {
        Self {
            failed: AtomicBool::new(false),
        }
    }

    /// Writes `line` and a newline to `out` in one write, unless a write
    /// failed before; a failure now stops all later lines.
    pub fn line(&self, out: &mut impl Write, line: fmt::Arguments<'_>) {
        if self.failed.load(Ordering::Relaxed) {
            return;
        }
        let text = format!("{line}\n");
        if out
            .write_all(text.as_bytes())
            .and_then(|()| out.flush())
            .is_err()
        {
            self.failed.store(true, Ordering::Relaxed);
        }
    }
}

/// Standard error, as a report stream.
static STDERR: ReportStream = ReportStream::new();

/// Writes a line on standard error (see [`note!`]), [`bounded`].
pub fn note_line(line: fmt::Arguments<'_>) {
    let text = line.to_string();
    STDERR.line(
        &mut std::io::stderr().lock(),
        format_args!("{}", bounded(&text)),
    );
}

/// The most characters of a line shown as it is: messages are shorter,
/// and a diagnostic's excerpt of a line is cut well before this.
const MAX_LINE_CHARS: usize = 400;

/// `text` with every line longer than [`MAX_LINE_CHARS`] shown with what
/// it quotes (between backticks, then between single quotes, as the
/// argument parser quotes) cut to about a line's width
/// ([`whitted::scene::quotes_cut`]): such a line quotes its input at
/// length, a name or value of megabytes. A line still too long keeps its
/// start and its end around a `…`. Shorter lines are left alone.
pub fn bounded(text: &str) -> Cow<'_, str> {
    if !text
        .lines()
        .any(|line| line.chars().nth(MAX_LINE_CHARS).is_some())
    {
        return Cow::Borrowed(text);
    }
    let lines: Vec<String> = text
        .split('\n')
        .map(|line| {
            if line.chars().nth(MAX_LINE_CHARS).is_none() {
                return line.to_string();
            }
            let cut = quotes_cut(&quotes_cut(line, '`'), '\'');
            let length = cut.chars().count();
            if length <= MAX_LINE_CHARS {
                return cut;
            }
            // Still too long (its input not quoted): its start and end,
            // which say what is wrong and why.
            let head: String = cut.chars().take(MAX_LINE_CHARS - 100).collect();
            let tail: String = cut.chars().skip(length - 99).collect();
            format!("{head}…{tail}")
        })
        .collect();
    Cow::Owned(lines.join("\n"))
}

/// Writes the command's results on standard output and flushes them; the
/// error says why they could not be written.
pub fn results(text: &str) -> Result<(), String> {
    check_results_stream()?;
    write_results(&mut std::io::stdout().lock(), text)
}

/// Refuses a standard output that was closed when the command started
/// (`>&-`): the runtime put `/dev/null` there, which would take the results
/// and lose them. A command that writes results checks this before its work.
pub fn check_results_stream() -> Result<(), String> {
    #[cfg(unix)]
    if crate::closed_streams::stdout_was_closed() {
        return Err(
            "standard output is closed (as with `>&-`), and this command writes its \
             results there; redirect it to a file, or to /dev/null to drop them"
                .to_string(),
        );
    }
    Ok(())
}

fn write_results(out: &mut impl Write, text: &str) -> Result<(), String> {
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| format!("the results could not be written to standard output: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stream that takes `room` bytes and then fails as a full device
    /// does, counting the writes tried.
    struct Full {
        room: usize,
        written: Vec<u8>,
        tries: usize,
    }

    impl Write for Full {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.tries += 1;
            let n = buf.len().min(self.room);
            if n == 0 {
                return Err(std::io::Error::from_raw_os_error(28));
            }
            self.room -= n;
            self.written.extend_from_slice(&buf[..n]);
            Ok(n)
        }

        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn reports_stop_at_the_first_failed_write_without_panicking() {
        let stream = ReportStream::new();
        let mut out = Full {
            room: 8,
            written: Vec::new(),
            tries: 0,
        };
        stream.line(&mut out, format_args!("first"));
        assert_eq!(out.written, b"first\n");
        stream.line(&mut out, format_args!("second {}", 2));
        let tries = out.tries;
        stream.line(&mut out, format_args!("third"));
        assert_eq!(out.tries, tries, "nothing is tried after a failure");
        assert_eq!(out.written, b"first\nse");
    }

    #[test]
    fn results_that_cannot_be_written_are_an_error_saying_why() {
        let mut out = Full {
            room: 3,
            written: Vec::new(),
            tries: 0,
        };
        let error = write_results(&mut out, "a table\n").unwrap_err();
        assert_eq!(
            error,
            "the results could not be written to standard output: No space left on device \
             (os error 28)"
        );
        let mut fine = Vec::new();
        write_results(&mut fine, "a table\n").unwrap();
        assert_eq!(fine, b"a table\n");
    }

    #[test]
    fn long_lines_quote_at_most_a_lines_width_and_short_ones_are_left_alone() {
        let short = "error: `x` is not a number\n  | `a a`\n";
        assert!(matches!(bounded(short), Cow::Borrowed(_)));
        let long = "b".repeat(100_000);
        let said = format!("error: invalid value '{long}' for '--x': `{long}` is wrong\nnext");
        let cut = format!("{}…", "b".repeat(71));
        assert_eq!(
            bounded(&said),
            format!("error: invalid value '{cut}' for '--x': `{cut}` is wrong\nnext")
        );
        // Not quoted: its start and end, 400 characters in all.
        let bare = format!("error: {long} is too large");
        let shown = bounded(&bare);
        assert_eq!(shown.chars().count(), 400);
        assert!(shown.starts_with("error: bbb") && shown.ends_with("bbb is too large"));
        assert!(shown.contains('…'));
    }
}
