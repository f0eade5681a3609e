//! NFF text as a stream of tokens: whitespace-separated words with their
//! byte ranges in the file, `#` comments removed. Lines do not matter: the
//! SPD writes a cone's eight numbers on the `c` line, the specification on
//! three lines, and both read the same.

use std::ops::Range;

/// One whitespace-separated word of the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Token<'a> {
    /// The word itself.
    pub(super) text: &'a str,
    /// Its bytes in the file.
    pub(super) span: Range<usize>,
}

/// The keywords that start an entity (`#` comments are removed earlier).
pub(super) const ENTITY_KEYWORDS: &[&str] = &["v", "b", "l", "f", "c", "s", "p", "pp"];

/// True when `text` starts an entity.
pub(super) fn is_entity_keyword(text: &str) -> bool {
    ENTITY_KEYWORDS.contains(&text)
}

/// The tokens of a file, in order.
#[derive(Clone, Debug)]
pub(super) struct Lexer<'a> {
    source: &'a str,
    position: usize,
}

impl<'a> Lexer<'a> {
    /// The tokens of `source`.
    pub(super) fn new(source: &'a str) -> Self {
        Self {
            source,
            position: 0,
        }
    }
}

impl<'a> Iterator for Lexer<'a> {
    type Item = Token<'a>;

    fn next(&mut self) -> Option<Token<'a>> {
        let bytes = self.source.as_bytes();
        loop {
            while bytes
                .get(self.position)
                .is_some_and(u8::is_ascii_whitespace)
            {
                self.position += 1;
            }
            if bytes.get(self.position) != Some(&b'#') {
                break;
            }
            while bytes.get(self.position).is_some_and(|&b| b != b'\n') {
                self.position += 1;
            }
        }
        let start = self.position;
        // ASCII bytes never occur inside a multi-byte character, so these
        // ends are always character boundaries.
        while bytes
            .get(self.position)
            .is_some_and(|&b| !b.is_ascii_whitespace() && b != b'#')
        {
            self.position += 1;
        }
        (self.position > start).then(|| Token {
            text: &self.source[start..self.position],
            span: start..self.position,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(source: &str) -> Vec<&str> {
        Lexer::new(source).map(|token| token.text).collect()
    }

    #[test]
    fn lines_do_not_matter_and_comments_are_dropped() {
        assert_eq!(
            words("# a cone\nc\n0 0 0 1 # base\n\t0 0 1 0.5\r\n#end"),
            ["c", "0", "0", "0", "1", "0", "0", "1", "0.5"]
        );
    }

    #[test]
    fn tokens_know_their_place_in_the_file() {
        let tokens: Vec<Token> = Lexer::new("s 1  é2#x\n 3").collect();
        let spans: Vec<Range<usize>> = tokens.iter().map(|t| t.span.clone()).collect();
        assert_eq!(spans, [0..1, 2..3, 5..8, 12..13]);
        assert_eq!(tokens[2].text, "é2");
    }

    #[test]
    fn empty_and_comment_only_files_have_no_tokens() {
        assert!(words("").is_empty());
        assert!(words("  \n# nothing\n#").is_empty());
    }
}
