//! Errors from reading a scene, split by whose fault they are, and located in
//! the file: `path:line:column`, the offending line, and a caret under the
//! offending span.
//!
//! ```text
//! scenes/bad.toml:12:10: error: expected a number for `radius`, found a string
//!    |
//! 12 | radius = "big"
//!    |          ^^^^^
//! ```
//!
//! Nothing here depends on the file format: any reader that knows the byte
//! range of a problem can build a [`Diagnostic`].

use std::collections::HashMap;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Why a scene could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("cannot read scene file `{}`: {source}", path.display())]
    Io {
        /// The file that could not be read.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The file's name says no format we read.
    #[error(
        "cannot read `{}`: unknown scene format; expected a file ending in {}",
        path.display(),
        extensions()
    )]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The camera asked for (by replacing parts of the scene's) is invalid.
    #[error("the camera asked for is invalid: {0}")]
    Camera(#[from] crate::render::CameraError),
    /// The file was read but what it says is wrong: every problem found, in
    /// the order they appear in the file.
    #[error("{}", summary(diagnostics))]
    Invalid {
        /// One entry per problem.
        diagnostics: Vec<Diagnostic>,
    },
}

/// The extensions of the scene formats, as `.toml or .nff`.
fn extensions() -> String {
    let names: Vec<String> = super::SCENE_EXTENSIONS
        .iter()
        .map(|e| format!(".{e}"))
        .collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// Every diagnostic, a blank line between them, then the count.
fn summary(diagnostics: &[Diagnostic]) -> String {
    let mut text = String::new();
    for diagnostic in diagnostics {
        text.push_str(&diagnostic.to_string());
        text.push_str("\n\n");
    }
    let count = diagnostics.len();
    text.push_str(&format!(
        "{count} error{}",
        if count == 1 { "" } else { "s" }
    ));
    text
}

/// How serious a [`Diagnostic`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// The file cannot be used as it is.
    Error,
    /// The file is read, but something in it is ignored or replaced.
    Warning,
}

/// One problem in a scene file, with where it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// An error or a warning.
    pub severity: Severity,
    /// The file, as it was named to the reader.
    pub path: PathBuf,
    /// Line of the problem, from 1.
    pub line: usize,
    /// Column of the problem, from 1, counted in characters.
    pub column: usize,
    /// What is wrong, and what was expected.
    pub message: String,
    /// The text of the offending line (without its line break). Of a line
    /// longer than [`MAX_SHOWN_CHARS`], only the part around the problem,
    /// with `…` where the line was cut.
    pub source_line: String,
    /// The column `source_line` starts at: 1, or where it was cut (the
    /// column of the leading `…`).
    pub shown_from: usize,
    /// How many characters of the line the problem covers (at least 1; a span
    /// running over several lines is cut at the end of its first line, and
    /// one running past a cut line's excerpt at its end).
    pub width: usize,
}

/// The longest source line a diagnostic shows whole. Of a longer one (a
/// whole file on one line) only this many characters around the problem are
/// kept, so that a diagnostic's size never depends on the file's.
pub const MAX_SHOWN_CHARS: usize = 160;

/// How many characters before the problem a cut line keeps.
const SHOWN_BEFORE: usize = 60;

/// The most errors, and separately the most warnings, one reader reports
/// for one file. Building a diagnostic takes time in proportion to its place
/// in the file, so a file with an error in every word would otherwise take
/// time quadratic in its size (and print as much).
pub const MAX_DIAGNOSTICS: usize = 100;

/// Adds the diagnostic `make` builds to `list`, unless `list` already holds
/// [`MAX_DIAGNOSTICS`] of that `severity`. The first diagnostic over the
/// limit is kept, its message replaced by one saying that reporting stopped
/// there; later ones are not even built.
pub fn push_limited(
    list: &mut Vec<Diagnostic>,
    severity: Severity,
    make: impl FnOnce() -> Diagnostic,
) {
    let count = list.iter().filter(|d| d.severity == severity).count();
    if count > MAX_DIAGNOSTICS {
        return;
    }
    let mut diagnostic = make();
    if count == MAX_DIAGNOSTICS {
        diagnostic.message = too_many(severity);
    }
    list.push(diagnostic);
}

/// The message of the diagnostic past [`MAX_DIAGNOSTICS`] of a severity.
fn too_many(severity: Severity) -> String {
    let kind = match severity {
        Severity::Error => "errors",
        Severity::Warning => "warnings",
    };
    format!(
        "too many {kind}: the first {MAX_DIAGNOSTICS} are reported, the rest from here on are not"
    )
}

/// The warnings of a scene and its side files (an OBJ's material
/// libraries), as they are to be reported: each message once per file, at
/// its first place, saying how many more places have it; at most
/// [`MAX_DIAGNOSTICS`] of them, then one saying that reporting stopped. A
/// list one reader already cut with [`push_limited`] stays cut where it
/// was.
pub fn limit_warnings(warnings: Vec<Diagnostic>) -> Vec<Diagnostic> {
    let stop = too_many(Severity::Warning);
    let mut first_place: HashMap<(PathBuf, String), usize> = HashMap::new();
    let mut kept: Vec<(Diagnostic, usize)> = Vec::new();
    let mut cut: Option<Diagnostic> = None;
    for warning in warnings {
        if warning.message == stop {
            cut.get_or_insert(warning);
            continue;
        }
        let key = (warning.path.clone(), warning.message.clone());
        match first_place.get(&key) {
            Some(&index) => kept[index].1 += 1,
            None => {
                first_place.insert(key, kept.len());
                kept.push((warning, 0));
            }
        }
    }
    if kept.len() > MAX_DIAGNOSTICS {
        let (mut first_cut, _) = kept.swap_remove(MAX_DIAGNOSTICS);
        kept.truncate(MAX_DIAGNOSTICS);
        first_cut.message = stop;
        cut.get_or_insert(first_cut);
    }
    let mut limited: Vec<Diagnostic> = kept
        .into_iter()
        .map(|(mut warning, more)| {
            if more > 0 {
                let places = if more == 1 { "place" } else { "places" };
                warning.message = format!("{} (and at {more} more {places})", warning.message);
            }
            warning
        })
        .collect();
    limited.extend(cut);
    limited
}

/// The part of `line` shown for a problem at `column`, and the column it
/// starts at (see [`Diagnostic::shown_from`]), with the index of the
/// character after its last.
fn excerpt(line: &str, column: usize) -> (String, usize, usize) {
    let length = line.chars().count();
    if length <= MAX_SHOWN_CHARS {
        return (line.to_string(), 1, length);
    }
    let first = column.saturating_sub(1).saturating_sub(SHOWN_BEFORE);
    let last = (first + MAX_SHOWN_CHARS).min(length);
    let mut text = String::new();
    if first > 0 {
        text.push('…');
    }
    text.extend(line.chars().skip(first).take(last - first));
    if last < length {
        text.push('…');
    }
    (text, first.max(1), last)
}

impl Diagnostic {
    /// The diagnostic for the bytes `span` of `source`, read from `path`.
    ///
    /// Spans past the end, reversed or splitting a character are tolerated:
    /// the caret lands on the nearest sensible place. A problem at the very
    /// end of a file that ends with a line break is shown at the end of the
    /// last line rather than on an empty line after it.
    pub fn new(path: &Path, source: &str, span: Range<usize>, message: impl Into<String>) -> Self {
        let mut start = span.start.min(source.len());
        if start == source.len() && source.ends_with('\n') {
            start -= 1;
        }
        while !source.is_char_boundary(start) {
            start -= 1;
        }
        let line_start = source[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = source[start..]
            .find('\n')
            .map_or(source.len(), |i| start + i);
        let mut end = span.end.clamp(start, line_end);
        while !source.is_char_boundary(end) {
            end += 1;
        }
        let column = source[line_start..start].chars().count() + 1;
        let line = source[line_start..line_end].trim_end_matches('\r');
        let (source_line, shown_from, shown_end) = excerpt(line, column);
        let width = source[start..end]
            .chars()
            .count()
            .min(shown_end.saturating_sub(column - 1))
            .max(1);
        Self {
            severity: Severity::Error,
            path: path.to_path_buf(),
            line: source[..line_start].matches('\n').count() + 1,
            column,
            message: readable(&message.into()),
            source_line: source_line.chars().map(visible).collect(),
            shown_from,
            width,
        }
    }
}

/// `message` with each text between a pair of `quote` characters longer
/// than [`MAX_QUOTED_CHARS`] cut to that many characters, the last `…`:
/// what a message quotes of its input is shown at about a line's width,
/// whatever the input. Diagnostics apply it with backticks; messages made
/// elsewhere (a command's own, a server's) may apply it too.
pub fn quotes_cut(message: &str, quote: char) -> String {
    let parts: Vec<&str> = message.split(quote).collect();
    let mut out = String::with_capacity(message.len().min(1 << 16));
    for (i, part) in parts.iter().enumerate() {
        if i > 0 {
            out.push(quote);
        }
        // Odd parts lie between a pair of backticks (the last one only when
        // its closing backtick is there).
        let quoted = i % 2 == 1 && i + 1 < parts.len();
        if quoted && part.chars().nth(MAX_QUOTED_CHARS).is_some() {
            out.extend(part.chars().take(MAX_QUOTED_CHARS - 1));
            out.push('…');
        } else {
            out.push_str(part);
        }
    }
    out
}

/// `c`, or where it is a control character that a terminal would act on
/// or hide (a NUL, an escape, a carriage return), its picture from
/// Unicode's Control Pictures block (`␀`, `␛`, `␍`): one character for one,
/// so a caret under the line stays in its place. Tabs are kept.
fn visible(c: char) -> char {
    match c {
        '\t' => c,
        '\u{0}'..='\u{1f}' => char::from_u32(0x2400 + c as u32).unwrap_or('\u{fffd}'),
        '\u{7f}' => '\u{2421}',
        _ => c,
    }
}

/// The most characters of a name or word quoted in a message (between
/// backticks): about a line's width; a longer one is cut, with `…`.
pub const MAX_QUOTED_CHARS: usize = 72;

/// A message as shown: control characters as [`visible`] makes them
/// (line breaks kept), numbers written out in more than 21 characters
/// (`-1e300` as 302 digits) in scientific notation, as Rust's shortest
/// form gives them (`-1e300`), and what it quotes between backticks cut to
/// [`MAX_QUOTED_CHARS`].
fn readable(message: &str) -> String {
    let cut = quotes_cut(message, '`');
    let message = cut.as_str();
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        let (before, from) = rest.split_at(start);
        let length = from
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(from.len());
        let (digits, after) = from.split_at(length);
        out.extend(
            before
                .chars()
                .map(|c| if c == '\n' { c } else { visible(c) }),
        );
        match digits.parse::<f64>() {
            Ok(value) if digits.len() > 21 && value.is_finite() => {
                out.push_str(&format!("{value:e}"));
            }
            _ => out.push_str(digits),
        }
        rest = after;
    }
    out.extend(rest.chars().map(|c| if c == '\n' { c } else { visible(c) }));
    out
}

impl Diagnostic {
    /// Like [`Diagnostic::new`], but a warning: the file is still read.
    pub fn warning(
        path: &Path,
        source: &str,
        span: Range<usize>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            severity: Severity::Warning,
            ..Self::new(path, source, span, message)
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let number = self.line.to_string();
        let gutter = " ".repeat(number.len());
        // Tabs before the caret are kept so it lines up under the text.
        let indent: String = self
            .source_line
            .chars()
            .take(self.column.saturating_sub(self.shown_from))
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        let severity = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        writeln!(
            f,
            "{}:{}:{}: {severity}: {}",
            self.path.display(),
            self.line,
            self.column,
            self.message
        )?;
        writeln!(f, "{gutter} |")?;
        if self.source_line.is_empty() {
            writeln!(f, "{number} |")?;
        } else {
            writeln!(f, "{number} | {}", self.source_line)?;
        }
        write!(f, "{gutter} | {indent}{}", "^".repeat(self.width))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(source: &str, span: Range<usize>) -> Diagnostic {
        Diagnostic::new(Path::new("scenes/bad.toml"), source, span, "oops")
    }

    #[test]
    fn control_characters_and_huge_numbers_are_shown_readably() {
        let source = "fov = 3\u{0}\u{1b}[2J\n";
        let d = Diagnostic::new(
            Path::new("s.toml"),
            source,
            6..10,
            format!(
                "expected a number, found `3\u{0}\u{1b}`; got {} and {} and {}",
                -1e300, 1e20, 0.000_000_1
            ),
        );
        assert_eq!(
            d.message,
            "expected a number, found `3␀␛`; got -1e300 and 100000000000000000000 and 0.0000001"
        );
        assert_eq!(d.source_line, "fov = 3␀␛[2J");
        let shown = d.to_string();
        assert!(
            shown.ends_with("1 | fov = 3␀␛[2J\n  |       ^^^^"),
            "{shown}"
        );
        assert!(!shown.contains('\u{0}') && !shown.contains('\u{1b}'));
        let long = "m".repeat(200_000);
        let named = Diagnostic::new(
            Path::new("s.toml"),
            source,
            0..1,
            format!("unknown material `{long}`; expected one of `a`, `b`"),
        );
        let cut = format!("{}…", "m".repeat(MAX_QUOTED_CHARS - 1));
        assert_eq!(
            named.message,
            format!("unknown material `{cut}`; expected one of `a`, `b`")
        );
    }

    #[test]
    fn shows_the_line_with_a_caret_under_the_span() {
        let source = "a = 1\n".repeat(11) + "radius = \"big\"\n";
        let start = source.find('"').unwrap();
        let d = Diagnostic::new(
            Path::new("scenes/bad.toml"),
            &source,
            start..start + 5,
            "expected a number for `radius`, found a string",
        );
        assert_eq!((d.line, d.column, d.width), (12, 10, 5));
        assert_eq!(
            d.to_string(),
            "scenes/bad.toml:12:10: error: expected a number for `radius`, found a string\n   \
             |\n12 | radius = \"big\"\n   |          ^^^^^"
        );
    }

    #[test]
    fn a_span_over_several_lines_is_cut_at_the_first_line_end() {
        let d = at("[camera]\neye = 1\n", 0..16);
        assert_eq!((d.line, d.column, d.width), (1, 1, 8));
        assert_eq!(d.source_line, "[camera]");
    }

    #[test]
    fn an_error_at_the_end_of_the_file_points_after_the_last_line() {
        let d = at("a = [1, 2\n", 10..13);
        assert_eq!((d.line, d.column, d.width), (1, 10, 1));
        assert_eq!(d.source_line, "a = [1, 2");
        let d = at("", 0..0);
        assert_eq!((d.line, d.column, d.width), (1, 1, 1));
        assert!(d.to_string().ends_with("1 |\n  | ^"));
    }

    #[test]
    fn reversed_spans_and_wide_characters_are_tolerated() {
        let d = at("a = 1.\n", Range { start: 6, end: 5 });
        assert_eq!((d.line, d.column, d.width), (1, 7, 1));
        let d = at("name = \"é\" # ü\nx", 8..10);
        assert_eq!((d.column, d.width), (9, 1));
        let d = at("é", 1..1);
        assert_eq!(d.column, 1);
    }

    #[test]
    fn of_a_very_long_line_only_the_part_around_the_problem_is_shown() {
        let source = format!("{}bad{}", "s ".repeat(5000), " x".repeat(5000));
        let d = at(&source, 10_000..10_003);
        assert_eq!((d.line, d.column, d.width), (1, 10_001, 3));
        assert_eq!(d.source_line.chars().count(), MAX_SHOWN_CHARS + 2);
        let shown = d.to_string();
        let caret = shown.lines().last().unwrap();
        let text = shown.lines().nth(2).unwrap();
        let caret_at = caret.chars().position(|c| c == '^').unwrap();
        let under: String = text.chars().skip(caret_at).take(3).collect();
        assert_eq!(under, "bad", "{shown}");
        assert!(
            text.starts_with("1 | …s s") && text.ends_with('…'),
            "{text}"
        );
        // Near the start, nothing is cut before; a long span stops at the cut.
        let d = at(&source, 2..source.len());
        assert_eq!((d.column, d.shown_from), (3, 1));
        assert_eq!(d.width, MAX_SHOWN_CHARS - 2);
        let carets = "^".repeat(MAX_SHOWN_CHARS - 2);
        assert!(d.to_string().ends_with(&format!(" |   {carets}")));
    }

    #[test]
    fn reporting_stops_after_the_most_diagnostics_of_a_severity() {
        let source = "x ".repeat(1000);
        let mut list = Vec::new();
        for i in 0..1000 {
            push_limited(&mut list, Severity::Error, || at(&source, 2 * i..2 * i + 1));
        }
        push_limited(&mut list, Severity::Warning, || {
            Diagnostic::warning(Path::new("a"), &source, 0..1, "still reported")
        });
        assert_eq!(list.len(), MAX_DIAGNOSTICS + 2);
        let last_error = &list[MAX_DIAGNOSTICS];
        assert_eq!(last_error.column, 2 * MAX_DIAGNOSTICS + 1);
        assert_eq!(
            last_error.message,
            "too many errors: the first 100 are reported, the rest from here on are not"
        );
        assert_eq!(list[MAX_DIAGNOSTICS + 1].message, "still reported");
    }

    #[test]
    fn warnings_are_reported_once_per_message_and_at_most_the_limit() {
        let source = "x ".repeat(1000);
        let warn = |i: usize, message: &str| {
            Diagnostic::warning(Path::new("a.obj"), &source, 2 * i..2 * i + 1, message)
        };
        let repeated = limit_warnings(vec![
            warn(0, "same"),
            warn(1, "other"),
            warn(2, "same"),
            warn(3, "same"),
            warn(4, "other"),
            warn(5, "alone"),
        ]);
        let shown: Vec<(usize, &str)> = repeated
            .iter()
            .map(|d| (d.column, d.message.as_str()))
            .collect();
        assert_eq!(
            shown,
            [
                (1, "same (and at 2 more places)"),
                (3, "other (and at 1 more place)"),
                (11, "alone")
            ]
        );
        let many = limit_warnings((0..500).map(|i| warn(i, &format!("w{i}"))).collect());
        assert_eq!(many.len(), MAX_DIAGNOSTICS + 1);
        assert_eq!(many[MAX_DIAGNOSTICS - 1].message, "w99");
        assert_eq!(many[MAX_DIAGNOSTICS].message, too_many(Severity::Warning));
        assert_eq!(many[MAX_DIAGNOSTICS].column, 2 * MAX_DIAGNOSTICS + 1);
        // A list a reader cut keeps its cut, once, after what it reported.
        let mut cut = Vec::new();
        for i in 0..300 {
            push_limited(&mut cut, Severity::Warning, || warn(i, &format!("w{i}")));
        }
        cut.push(warn(400, "from another file"));
        cut.push(warn(401, &too_many(Severity::Warning)));
        let limited = limit_warnings(cut);
        assert_eq!(limited.len(), MAX_DIAGNOSTICS + 1);
        assert_eq!(limited[MAX_DIAGNOSTICS].column, 2 * MAX_DIAGNOSTICS + 1);
        let few = limit_warnings(vec![warn(0, "a"), warn(1, &too_many(Severity::Warning))]);
        assert_eq!(few.len(), 2);
        assert_eq!(few[1].message, too_many(Severity::Warning));
    }

    #[test]
    fn warnings_say_so() {
        let d = Diagnostic::warning(Path::new("a.obj"), "x 1", 0..1, "ignored");
        assert!(d.to_string().starts_with("a.obj:1:1: warning: ignored\n"));
    }

    #[test]
    fn tabs_before_the_caret_are_kept() {
        let d = at("\tx = 1", 1..2);
        assert!(d.to_string().ends_with(" | \t^"));
    }

    #[test]
    fn crlf_line_ends_are_not_shown() {
        let d = at("a = 1\r\nb = x\r\n", 11..12);
        assert_eq!((d.line, d.column), (2, 5));
        assert_eq!(d.source_line, "b = x");
    }

    #[test]
    fn invalid_lists_every_diagnostic_then_the_count() {
        let one = at("a = 1", 0..1);
        let error = SceneError::Invalid {
            diagnostics: vec![one.clone(), one.clone()],
        };
        assert_eq!(error.to_string(), format!("{one}\n\n{one}\n\n2 errors"));
        let error = SceneError::Invalid {
            diagnostics: vec![one.clone()],
        };
        assert_eq!(error.to_string(), format!("{one}\n\n1 error"));
    }
}
