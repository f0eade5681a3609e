//! File names in OBJ and MTL statements, as exporters write them: a
//! backslash before a space escapes it (`my\ file.mtl`), any other
//! backslash is a folder separator (`textures\wood.png`), and one `mtllib`
//! line may name several libraries (`mtllib a.mtl b.mtl`).
//!
//! A name with plain spaces (`mtllib my file.mtl`) and several names on
//! one line look alike; the file system decides: the whole rest of the line
//! is one name when it names an existing file, and otherwise the line is
//! split at its unescaped spaces.

use std::ops::Range;
use std::path::{Path, PathBuf};

/// The path a file name in a statement stands for: `\ ` read as a space,
/// other backslashes as `/`.
pub(super) fn file_path(name: &str) -> PathBuf {
    let mut path = String::with_capacity(name.len());
    let mut chars = name.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek().is_some_and(|next| next.is_whitespace()) => {
                path.extend(chars.next());
            }
            '\\' => path.push('/'),
            c => path.push(c),
        }
    }
    PathBuf::from(path)
}

/// The words of `text`, split at whitespace no backslash escapes, each
/// with its span, `text` starting at byte `start` of the file.
fn unescaped_words(text: &str, start: usize) -> Vec<(&str, Range<usize>)> {
    let mut words = Vec::new();
    let mut begin = None;
    let mut escaped = false;
    for (i, c) in text.char_indices() {
        if c.is_whitespace() && !escaped {
            if let Some(b) = begin.take() {
                words.push((&text[b..i], start + b..start + i));
            }
        } else {
            begin.get_or_insert(i);
        }
        escaped = c == '\\' && !escaped;
    }
    if let Some(b) = begin {
        words.push((&text[b..], start + b..start + text.len()));
    }
    words
}

/// The libraries of an `mtllib` statement whose names are `text` (the rest
/// of the line, at `span` in the file), as paths in `folder` with the span
/// of each name: the whole text when it names an existing file, otherwise
/// each name between unescaped spaces.
pub(super) fn library_paths(
    text: &str,
    span: Range<usize>,
    folder: &Path,
) -> Vec<(PathBuf, Range<usize>)> {
    let whole = folder.join(file_path(text));
    if whole.is_file() {
        return vec![(whole, span)];
    }
    unescaped_words(text, span.start)
        .into_iter()
        .map(|(name, at)| (folder.join(file_path(name)), at))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaped_spaces_are_spaces_and_other_backslashes_separate_folders() {
        assert_eq!(file_path(r"my\ file.mtl"), Path::new("my file.mtl"));
        assert_eq!(
            file_path(r"textures\wood grain.png"),
            Path::new("textures/wood grain.png")
        );
        assert_eq!(file_path(r"a\\b"), Path::new("a//b"));
        assert_eq!(file_path("plain.mtl"), Path::new("plain.mtl"));
    }

    #[test]
    fn a_line_is_split_at_unescaped_spaces_unless_it_names_a_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path();
        let text = r"a.mtl  my\ b.mtl c.mtl";
        let names = library_paths(text, 10..10 + text.len(), folder);
        assert_eq!(
            names,
            [
                (folder.join("a.mtl"), 10..15),
                (folder.join("my b.mtl"), 17..26),
                (folder.join("c.mtl"), 27..32),
            ]
        );
        std::fs::write(folder.join("my library.mtl"), "").unwrap();
        assert_eq!(
            library_paths("my library.mtl", 0..14, folder),
            [(folder.join("my library.mtl"), 0..14)]
        );
    }
}
