//! The UTF-8 byte-order mark some editors (Notepad among them) and
//! exporters write at the start of a text file. Every reader takes its text
//! through [`without_bom`] before reading a word, so a mark is never read as
//! part of the first statement (an OBJ's first vertex, an NFF's first
//! entity). Spans are then counted from after the mark, which is invisible,
//! so columns in messages are the ones an editor shows.

/// The byte-order mark, U+FEFF, as it starts a UTF-8 text.
pub const BYTE_ORDER_MARK: char = '\u{feff}';

/// `text` without the one byte-order mark it may start with.
pub fn without_bom(text: &str) -> &str {
    text.strip_prefix(BYTE_ORDER_MARK).unwrap_or(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_leading_mark_is_removed_and_nothing_else() {
        assert_eq!(without_bom("\u{feff}v 1 2 3"), "v 1 2 3");
        assert_eq!(without_bom("v 1 2 3"), "v 1 2 3");
        assert_eq!(without_bom("\u{feff}\u{feff}x"), "\u{feff}x");
        assert_eq!(without_bom("a\u{feff}"), "a\u{feff}");
        assert_eq!(without_bom(""), "");
    }
}
