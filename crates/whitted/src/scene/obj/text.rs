//! Lines and whitespace-separated words of OBJ and MTL text, each with its
//! byte range in the file (for messages).

use std::ops::Range;

/// One line of a file: its text without the line break or a `#` comment,
/// and where it starts in the file.
#[derive(Clone, Copy, Debug)]
pub(super) struct Line<'a> {
    /// The text, comment and line break removed.
    pub(super) text: &'a str,
    /// Byte offset of the line's first character in the file.
    pub(super) start: usize,
}

impl<'a> Line<'a> {
    /// The words of the line with their spans in the file.
    pub(super) fn words(&self) -> Words<'a> {
        Words {
            text: self.text,
            start: self.start,
            position: 0,
        }
    }

    /// The text after the first word, trimmed, with its span: names that
    /// may hold spaces (`usemtl`, `newmtl`, `mtllib`).
    pub(super) fn rest(&self) -> (&'a str, Range<usize>) {
        let mut words = self.words();
        let after = words.next().map_or(0, |(_, span)| span.end - self.start);
        let tail = &self.text[after..];
        let trimmed_start = tail.len() - tail.trim_start().len();
        let text = tail.trim();
        let begin = self.start + after + trimmed_start;
        (text, begin..begin + text.len())
    }
}

/// The lines of `source`.
pub(super) fn lines(source: &str) -> impl Iterator<Item = Line<'_>> {
    let mut start = 0;
    source.split('\n').map(move |raw| {
        let line_start = start;
        start += raw.len() + 1;
        let text = raw.split('#').next().unwrap_or("").trim_end_matches('\r');
        Line {
            text,
            start: line_start,
        }
    })
}

/// Words of a line and their spans.
pub(super) struct Words<'a> {
    text: &'a str,
    start: usize,
    position: usize,
}

impl<'a> Iterator for Words<'a> {
    type Item = (&'a str, Range<usize>);

    fn next(&mut self) -> Option<Self::Item> {
        let rest = &self.text[self.position..];
        let begin = self.position + (rest.len() - rest.trim_start().len());
        let length = self.text[begin..]
            .find(char::is_whitespace)
            .unwrap_or(self.text.len() - begin);
        if length == 0 {
            self.position = self.text.len();
            return None;
        }
        self.position = begin + length;
        let at = self.start + begin;
        Some((&self.text[begin..begin + length], at..at + length))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_carry_their_place_in_the_file_and_comments_are_dropped() {
        let source = "v 1 2 3\n  usemtl  my wood  # oak\r\n";
        let all: Vec<Line<'_>> = lines(source).collect();
        let words: Vec<_> = all[0].words().collect();
        assert_eq!(words[1], ("1", 2..3));
        let (name, span) = all[1].rest();
        assert_eq!(name, "my wood");
        assert_eq!(&source[span], "my wood");
        assert_eq!(all[1].words().count(), 3);
        assert_eq!(all[2].words().count(), 0);
    }
}
