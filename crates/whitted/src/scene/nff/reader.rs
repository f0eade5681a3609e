//! Reading values from the token stream, recording every problem with its
//! place in the file.
//!
//! A value that cannot be read is reported and the entity abandoned; the
//! caller then skips to the next entity keyword ([`Reader::skip_to_entity`])
//! and carries on, so one file gives all its errors at once. A keyword met
//! where a number was expected is reported but not consumed: it starts the
//! next entity.

use std::iter::Peekable;
use std::ops::Range;
use std::path::Path;

use super::lexer::{Lexer, Token, is_entity_keyword};
use crate::math::{Vec3, magnitude};
use crate::scene::{Diagnostic, Severity, WholeNumberError, parse_whole_number, push_limited};
use crate::shading::{Color, factor};

/// A problem that has been recorded; the entity being read is abandoned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Reported;

/// The result of reading a value: the value, or a problem already recorded.
pub(super) type Parsed<T> = Result<T, Reported>;

/// The token stream of one file and the problems found in it.
pub(super) struct Reader<'a> {
    source: &'a str,
    path: &'a Path,
    tokens: Peekable<Lexer<'a>>,
    /// End of the last token taken: where an entity being read ends.
    last_end: usize,
    /// Every problem (up to the limit of [`push_limited`]).
    diagnostics: Vec<Diagnostic>,
}

impl<'a> Reader<'a> {
    /// A reader of `source`, named `path` in messages.
    pub(super) fn new(source: &'a str, path: &'a Path) -> Self {
        Self {
            source,
            path,
            tokens: Lexer::new(source).peekable(),
            last_end: 0,
            diagnostics: Vec::new(),
        }
    }

    /// Records a problem at `span`.
    pub(super) fn error(&mut self, span: Range<usize>, message: impl Into<String>) -> Reported {
        let (path, source) = (self.path, self.source);
        push_limited(&mut self.diagnostics, Severity::Error, || {
            Diagnostic::new(path, source, span, message)
        });
        Reported
    }

    /// Every problem recorded, in the order they appear in the file.
    pub(super) fn into_diagnostics(mut self) -> Vec<Diagnostic> {
        self.diagnostics.sort_by_key(|d| (d.line, d.column));
        self.diagnostics
    }

    /// The next token, taken.
    pub(super) fn next_token(&mut self) -> Option<Token<'a>> {
        let token = self.tokens.next()?;
        self.last_end = token.span.end;
        Some(token)
    }

    /// The bytes from `start` to the end of the last token taken: the span
    /// of an entity read so far.
    pub(super) fn since(&self, start: usize) -> Range<usize> {
        start..self.last_end.max(start)
    }

    /// Skips tokens up to the next entity keyword (left for the caller).
    pub(super) fn skip_to_entity(&mut self) {
        while self
            .tokens
            .peek()
            .is_some_and(|token| !is_entity_keyword(token.text))
        {
            self.next_token();
        }
    }

    /// Where the next token starts (the end of the file when there is none).
    pub(super) fn next_start(&mut self) -> usize {
        let end = self.source.len();
        self.tokens.peek().map_or(end, |token| token.span.start)
    }

    /// True when the next token reads as a number (finite or not).
    pub(super) fn at_number(&mut self) -> bool {
        self.tokens
            .peek()
            .is_some_and(|token| token.text.parse::<f64>().is_ok())
    }

    /// Takes the next token for `what`, or reports that it is missing. A
    /// keyword is reported but left in place.
    fn take(&mut self, kind: &str, what: &str) -> Parsed<Token<'a>> {
        let keyword = match self.tokens.peek() {
            None => None,
            Some(token) if is_entity_keyword(token.text) => Some(token.clone()),
            Some(_) => return self.next_token().ok_or(Reported),
        };
        let (span, found) = match keyword {
            None => {
                let end = self.source.len();
                (end..end, "the end of the file".to_string())
            }
            Some(token) => (token.span, format!("`{}`", token.text)),
        };
        Err(self.error(span, format!("expected {kind} for {what}, found {found}")))
    }

    /// A finite number within ±[`magnitude::MAX_COORDINATE`] (beyond it,
    /// squares in intersection overflow), for `what` ("the sphere's
    /// radius").
    pub(super) fn number(&mut self, what: &str) -> Parsed<f64> {
        let token = self.take("a number", what)?;
        match token.text.parse::<f64>() {
            Ok(value) if value.is_finite() => magnitude::coordinate(value).map_err(|error| {
                self.error(token.span, format!("{what} is out of range: {error}"))
            }),
            Ok(_) => Err(self.error(
                token.span,
                format!(
                    "expected a finite number for {what}, found `{}`",
                    token.text
                ),
            )),
            Err(_) => Err(self.error(
                token.span,
                format!("expected a number for {what}, found `{}`", token.text),
            )),
        }
    }

    /// Three numbers, for `what`.
    pub(super) fn vec3(&mut self, what: &str) -> Parsed<Vec3> {
        Ok(Vec3::new(
            self.number(what)?,
            self.number(what)?,
            self.number(what)?,
        ))
    }

    /// Three numbers that are not negative and at most
    /// [`factor::MAX_FACTOR`], for the colour `what`.
    pub(super) fn color(&mut self, what: &str) -> Parsed<Color> {
        let start = self.next_start();
        let color = Color::from(self.vec3(what)?.to_array());
        if color.min_element() < 0.0 {
            let span = self.since(start);
            return Err(self.error(span, format!("{what} must not be negative, got {color}")));
        }
        if let Err(error) = factor::factor(color.max_element()) {
            let span = self.since(start);
            return Err(self.error(span, format!("{what} is out of range: {error}")));
        }
        Ok(color)
    }

    /// A whole number from `least` to `most`, for `what`, with its span. A
    /// number out of range is reported as such, however many digits it has.
    pub(super) fn count(
        &mut self,
        what: &str,
        least: u32,
        most: u32,
    ) -> Parsed<(u32, Range<usize>)> {
        let token = self.take("a whole number", what)?;
        let text = token.text;
        let message = match parse_whole_number(text, least.into(), most.into()) {
            Ok(value) => return Ok((value as u32, token.span)),
            Err(WholeNumberError::NotANumber | WholeNumberError::NotWhole) => {
                format!("expected a whole number for {what}, found `{text}`")
            }
            Err(WholeNumberError::Negative | WholeNumberError::BelowMinimum) => {
                format!("{what} must be at least {least}, got {text}")
            }
            Err(WholeNumberError::AboveMaximum) => {
                format!("{what} must be at most {most}, got {text}")
            }
        };
        Err(self.error(token.span, message))
    }

    /// The word `word`, which must come next in the `v` block.
    pub(super) fn word(&mut self, word: &str) -> Parsed<()> {
        let token = self.take(&format!("`{word}`"), "the view")?;
        if token.text == word {
            Ok(())
        } else {
            Err(self.error(
                token.span,
                format!("expected `{word}` in the view, found `{}`", token.text),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reader(source: &str) -> Reader<'_> {
        Reader::new(source, Path::new("t.nff"))
    }

    fn messages(r: Reader<'_>) -> Vec<String> {
        r.into_diagnostics()
            .into_iter()
            .map(|d| format!("{}:{}: {}", d.line, d.column, d.message))
            .collect()
    }

    #[test]
    fn numbers_and_counts_are_read_and_checked() {
        let mut r = reader("1.5 -2e3 abc nan 4 2.5 1 -7 18446744073709551616 11");
        assert_eq!(r.number("x"), Ok(1.5));
        assert_eq!(r.number("x"), Ok(-2000.0));
        assert_eq!(r.number("the sphere's radius"), Err(Reported));
        assert_eq!(r.number("y"), Err(Reported));
        assert_eq!(r.count("n", 3, 10).map(|c| c.0), Ok(4));
        for _ in 0..5 {
            assert_eq!(r.count("n", 3, 10), Err(Reported));
        }
        assert_eq!(
            messages(r),
            [
                "1:10: expected a number for the sphere's radius, found `abc`",
                "1:14: expected a finite number for y, found `nan`",
                "1:20: expected a whole number for n, found `2.5`",
                "1:24: n must be at least 3, got 1",
                "1:26: n must be at least 3, got -7",
                "1:29: n must be at most 10, got 18446744073709551616",
                "1:50: n must be at most 10, got 11",
            ]
        );
    }

    #[test]
    fn a_keyword_where_a_number_belongs_is_left_for_the_next_entity() {
        let mut r = reader("1 2\ns 3");
        assert_eq!(r.vec3("the centre"), Err(Reported));
        assert_eq!(r.next_token().map(|t| t.text), Some("s"));
        assert_eq!(r.number("r"), Ok(3.0));
        assert_eq!(r.number("r"), Err(Reported));
        assert_eq!(
            messages(r),
            [
                "2:1: expected a number for the centre, found `s`",
                "2:4: expected a number for r, found the end of the file",
            ]
        );
    }

    #[test]
    fn skipping_stops_before_the_next_keyword() {
        let mut r = reader("1 x 2\n  p 3");
        r.skip_to_entity();
        let p = r.next_token().unwrap();
        assert_eq!((p.text, p.span.clone()), ("p", 8..9));
        assert_eq!(r.since(p.span.start), 8..9);
    }

    #[test]
    fn colours_are_not_negative() {
        let mut r = reader("0.5 -1 0");
        assert_eq!(r.color("the background colour"), Err(Reported));
        assert_eq!(
            messages(r),
            ["1:1: the background colour must not be negative, got [0.5, -1, 0]"]
        );
    }
}
