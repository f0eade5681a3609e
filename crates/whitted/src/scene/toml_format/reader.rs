//! Walking a parsed TOML document: typed values, each error recorded at the
//! span of the offending key or value, and the walk carried on so that every
//! error of a file is reported at once.
//!
//! A reading step returns [`Parsed`]: the value, or [`Reported`] when it was
//! wrong and its error is already recorded. Steps that do not depend on each
//! other are all run before their results are combined with `?`.

use std::path::Path;
use std::sync::Arc;

use toml_span::Span;
use toml_span::value::{Key, Table, Value};

use crate::image::ColorSpace;
use crate::math::{Vec3, magnitude, unit};
use crate::render::LineIndex;
use crate::scene::{Diagnostic, SceneError, Severity, push_limited};
use crate::shading::texture::{Decoding, ImageCache, ImageData};
use crate::shading::{Color, factor};

/// A value was wrong and its error has been recorded. Only [`Reader::error`]
/// makes one, so a failed walk always has at least one diagnostic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Reported(());

/// The outcome of one reading step.
pub(super) type Parsed<T> = Result<T, Reported>;

/// Runs every step, then keeps all the values or reports failure.
pub(super) fn all<T>(steps: impl IntoIterator<Item = Parsed<T>>) -> Parsed<Vec<T>> {
    let results: Vec<Parsed<T>> = steps.into_iter().collect();
    results.into_iter().collect()
}

/// Both values, or failure when either step failed (both already ran).
pub(super) fn both<A, B>(a: Parsed<A>, b: Parsed<B>) -> Parsed<(A, B)> {
    Ok((a?, b?))
}

/// The state of a walk: the text (for spans) and the errors found so far.
pub(super) struct Reader<'s> {
    source: &'s str,
    path: &'s Path,
    diagnostics: Vec<Diagnostic>,
    /// Warnings: the file is still read.
    warnings: Vec<Diagnostic>,
    /// Images decoded so far, shared by every material naming them.
    images: ImageCache,
    /// How colour images are decoded: through the sRGB curve for a linear
    /// scene, as stored for a display-referred one.
    color_images: Decoding,
}

/// A TOML table being read, with what to call it in messages.
pub(super) struct Fields<'t, 's> {
    table: &'t Table<'s>,
    /// Where the table starts: its `[header]` or its `{`.
    span: Span,
    /// Its name in messages: `object`, `[camera]`, ``material `glass` ``.
    what: String,
}

impl<'t, 's> Fields<'t, 's> {
    /// The value of `key`, if present.
    pub(super) fn get(&self, key: &str) -> Option<&'t Value<'s>> {
        self.table.get(key)
    }

    /// The key and value, in the order they appear in the file.
    pub(super) fn entries_in_file_order(&self) -> Vec<(&'t Key<'s>, &'t Value<'s>)> {
        let mut entries: Vec<_> = self.table.iter().collect();
        entries.sort_by_key(|(key, _)| key.span.start);
        entries
    }

    /// Calls the table `what` in later messages, once it is known what it is.
    pub(super) fn rename(&mut self, what: impl Into<String>) {
        self.what = what.into();
    }

    /// Where the table starts, for errors about the table as a whole.
    pub(super) fn span(&self) -> Span {
        self.span
    }
}

/// How to describe the type of a TOML value in a message.
fn type_name(value: &Value<'_>) -> &'static str {
    if value.as_str().is_some() {
        "a string"
    } else if value.as_integer().is_some() {
        "an integer"
    } else if value.as_float().is_some() {
        "a float"
    } else if value.as_bool().is_some() {
        "a boolean"
    } else if value.as_array().is_some() {
        "an array"
    } else {
        "a table"
    }
}

/// `a, b, c` for a list of allowed keys or names.
pub(super) fn list(names: &[&str]) -> String {
    names.join(", ")
}

impl<'s> Reader<'s> {
    /// A walk over `source`, read from `path`.
    pub(super) fn new(source: &'s str, path: &'s Path) -> Self {
        Self {
            source,
            path,
            diagnostics: Vec::new(),
            warnings: Vec::new(),
            images: ImageCache::default(),
            color_images: Decoding::Color,
        }
    }

    /// The walk, noting images that take more than `bytes` as textures
    /// (for tests of the note).
    #[cfg(test)]
    pub(super) fn noting_images_above(mut self, bytes: u64) -> Self {
        self.images = ImageCache::noting_above(bytes);
        self
    }

    /// Takes the scene's colours to mean `color_space` from now on: colour
    /// images are then decoded into the same space.
    pub(super) fn set_color_space(&mut self, color_space: ColorSpace) {
        self.color_images = match color_space {
            ColorSpace::Linear => Decoding::Color,
            ColorSpace::Display => Decoding::Data,
        };
    }

    /// How a colour image is decoded.
    pub(super) fn color_image_decoding(&self) -> Decoding {
        self.color_images
    }

    /// The image file named `name` (relative to the scene file), decoded
    /// once as `decoding`; an error at `span` naming the file when it cannot
    /// be read, and a warning there when it is first decoded into a large
    /// texture ([`ImageCache::load_noting`]).
    pub(super) fn image(
        &mut self,
        name: &str,
        span: Span,
        decoding: Decoding,
    ) -> Parsed<Arc<ImageData>> {
        let file = self.path.parent().unwrap_or(Path::new("")).join(name);
        let (image, note) = self
            .images
            .load_noting(&file, name, decoding)
            .map_err(|error| self.error(span, error.to_string()))?;
        if let Some(note) = note {
            let (path, source) = (self.path, self.source);
            push_limited(&mut self.warnings, Severity::Warning, || {
                Diagnostic::warning(path, source, span.start..span.end, note)
            });
        }
        Ok(image)
    }

    /// The file `name`, relative to the scene file's folder.
    pub(super) fn beside(&self, name: &str) -> std::path::PathBuf {
        self.path.parent().unwrap_or(Path::new("")).join(name)
    }

    /// Passes on the warnings of a file this one reads (a model), each at
    /// its own place, once: a file read again (a material library two
    /// models share) does not repeat them.
    pub(super) fn pass_on_warnings(&mut self, warnings: Vec<Diagnostic>) {
        for warning in warnings {
            if !self.warnings.contains(&warning) {
                push_limited(&mut self.warnings, Severity::Warning, || warning);
            }
        }
    }

    /// Records an error at `span`.
    pub(super) fn error(&mut self, span: Span, message: impl Into<String>) -> Reported {
        let (path, source) = (self.path, self.source);
        push_limited(&mut self.diagnostics, Severity::Error, || {
            Diagnostic::new(path, source, span.start..span.end, message)
        });
        Reported(())
    }

    /// The result of the walk: `value` when nothing was wrong, otherwise
    /// every error in the order they appear in the file; with the warnings,
    /// in the same order.
    pub(super) fn finish_with_warnings<T>(
        mut self,
        value: Parsed<T>,
    ) -> Result<(T, Vec<Diagnostic>), SceneError> {
        match value {
            Ok(value) if self.diagnostics.is_empty() => {
                // Grouped by file (a model's are passed on), in order.
                self.warnings
                    .sort_by(|a, b| (&a.path, a.line, a.column).cmp(&(&b.path, b.line, b.column)));
                Ok((value, self.warnings))
            }
            _ => {
                self.diagnostics.sort_by_key(|d| (d.line, d.column));
                Err(SceneError::Invalid {
                    diagnostics: self.diagnostics,
                })
            }
        }
    }

    /// The lines of the file, to locate its objects.
    pub(super) fn line_index(&self) -> LineIndex<'s> {
        LineIndex::new(self.source)
    }

    /// The text of the file at `span` (empty when out of bounds).
    pub(super) fn raw(&self, span: Span) -> &'s str {
        self.source.get(span.start..span.end).unwrap_or("")
    }

    /// The span of a value as written: a string's span includes its quotes.
    pub(super) fn span_of(&self, value: &Value<'_>) -> Span {
        let span = value.span;
        if value.as_str().is_none() {
            return span;
        }
        let before = self.source.get(..span.start).unwrap_or("");
        let after = self.source.get(span.end..).unwrap_or("");
        for quote in ["\"\"\"", "'''", "\"", "'"] {
            if before.ends_with(quote) && after.starts_with(quote) {
                return Span::new(span.start - quote.len(), span.end + quote.len());
            }
        }
        span
    }

    /// Records a type error: "expected `expected` for `key`, found ...".
    pub(super) fn wrong_type(&mut self, value: &Value<'_>, key: &str, expected: &str) -> Reported {
        let span = self.span_of(value);
        self.error(
            span,
            format!(
                "expected {expected} for `{key}`, found {}",
                type_name(value)
            ),
        )
    }

    /// The table `value`, to be called `what` in messages.
    pub(super) fn table<'t, 'd>(
        &mut self,
        value: &'t Value<'d>,
        key: &str,
        what: impl Into<String>,
    ) -> Parsed<Fields<'t, 'd>> {
        match value.as_table() {
            Some(table) => Ok(Fields {
                table,
                span: value.span,
                what: what.into(),
            }),
            None => Err(self.wrong_type(value, key, "a table")),
        }
    }

    /// The array `value`; `expected` names what it should hold, for the
    /// message when it is something else.
    pub(super) fn array<'t, 'd>(
        &mut self,
        value: &'t Value<'d>,
        key: &str,
        expected: &str,
    ) -> Parsed<&'t [Value<'d>]> {
        match value.as_array() {
            Some(items) => Ok(items),
            None => Err(self.wrong_type(value, key, expected)),
        }
    }

    /// Records an error for every key of `fields` not in `allowed`.
    pub(super) fn check_keys(&mut self, fields: &Fields<'_, '_>, allowed: &[&str]) -> Parsed<()> {
        let expected = format!("expected one of: {}", list(allowed));
        self.check_keys_saying(fields, allowed, &expected)
    }

    /// Records an error for every key of `fields` not in `allowed`, its
    /// message ending with `expected` (what the keys could have been).
    pub(super) fn check_keys_saying(
        &mut self,
        fields: &Fields<'_, '_>,
        allowed: &[&str],
        expected: &str,
    ) -> Parsed<()> {
        let mut result = Ok(());
        for key in fields.table.keys() {
            if !allowed.contains(&key.name.as_ref()) {
                result = Err(self.error(
                    key.span,
                    format!("unknown key `{}` in {}; {expected}", key.name, fields.what),
                ));
            }
        }
        result
    }

    /// Records an error for every key of `fields` that none of its possible
    /// kinds has, when which kind it is could not be read: `keys_of_kinds`
    /// gives the keys of each kind, `kinds` names them in the message
    /// ("light types", "shapes").
    pub(super) fn check_keys_of_any_kind(
        &mut self,
        fields: &Fields<'_, '_>,
        keys_of_kinds: &[&[&str]],
        kinds: &str,
    ) -> Parsed<()> {
        let mut allowed: Vec<&str> = Vec::new();
        for key in keys_of_kinds.iter().copied().flatten() {
            if !allowed.contains(key) {
                allowed.push(key);
            }
        }
        let expected = format!(
            "none of the {kinds} has it; expected one of: {}",
            list(&allowed)
        );
        self.check_keys_saying(fields, &allowed, &expected)
    }

    /// The span of the value of `key`, or of the table when it is absent.
    pub(super) fn value_span(&self, fields: &Fields<'_, '_>, key: &str) -> Span {
        fields
            .get(key)
            .map_or(fields.span, |value| self.span_of(value))
    }

    /// The value of `key` read by `read`, or `None` when absent.
    pub(super) fn optional<'t, 'd, T>(
        &mut self,
        fields: &Fields<'t, 'd>,
        key: &str,
        read: impl FnOnce(&mut Self, &'t Value<'d>, &str) -> Parsed<T>,
    ) -> Parsed<Option<T>> {
        fields
            .get(key)
            .map(|value| read(self, value, key))
            .transpose()
    }

    /// The value of `key` read by `read`, or `default` when absent.
    pub(super) fn or_default<'t, 'd, T>(
        &mut self,
        fields: &Fields<'t, 'd>,
        key: &str,
        default: T,
        read: impl FnOnce(&mut Self, &'t Value<'d>, &str) -> Parsed<T>,
    ) -> Parsed<T> {
        Ok(self.optional(fields, key, read)?.unwrap_or(default))
    }

    /// The value of `key` read by `read`; an error when absent.
    pub(super) fn require<'t, 'd, T>(
        &mut self,
        fields: &Fields<'t, 'd>,
        key: &str,
        read: impl FnOnce(&mut Self, &'t Value<'d>, &str) -> Parsed<T>,
    ) -> Parsed<T> {
        match fields.get(key) {
            Some(value) => read(self, value, key),
            None => Err(self.error(
                fields.span,
                format!("missing required key `{key}` in {}", fields.what),
            )),
        }
    }

    /// A finite number (an integer or a float).
    pub(super) fn number(&mut self, value: &Value<'_>, key: &str) -> Parsed<f64> {
        let number = if let Some(i) = value.as_integer() {
            i as f64
        } else if let Some(x) = value.as_float() {
            x
        } else {
            return Err(self.wrong_type(value, key, "a number"));
        };
        if number.is_finite() {
            Ok(number)
        } else {
            Err(self.error(
                value.span,
                format!("expected a finite number for `{key}`, found {number}"),
            ))
        }
    }

    /// A number `>= 0`.
    pub(super) fn non_negative(&mut self, value: &Value<'_>, key: &str) -> Parsed<f64> {
        let number = self.number(value, key)?;
        if number >= 0.0 {
            Ok(number)
        } else {
            Err(self.error(
                value.span,
                format!("`{key}` must not be negative, got {number}"),
            ))
        }
    }

    /// A number `> 0`.
    pub(super) fn positive(&mut self, value: &Value<'_>, key: &str) -> Parsed<f64> {
        let number = self.number(value, key)?;
        if number > 0.0 {
            Ok(number)
        } else {
            Err(self.error(
                value.span,
                format!("`{key}` must be greater than 0, got {number}"),
            ))
        }
    }

    /// An integer from `min` to `max`.
    pub(super) fn count(
        &mut self,
        value: &Value<'_>,
        key: &str,
        min: u32,
        max: u32,
    ) -> Parsed<u32> {
        let Some(integer) = value.as_integer() else {
            return Err(self.wrong_type(value, key, "an integer"));
        };
        if integer < i64::from(min) {
            return Err(self.error(
                value.span,
                format!("`{key}` must be at least {min}, got {integer}"),
            ));
        }
        if integer > i64::from(max) {
            return Err(self.error(
                value.span,
                format!("`{key}` must be at most {max}, got {integer}"),
            ));
        }
        Ok(integer as u32)
    }

    /// `true` or `false`.
    pub(super) fn boolean(&mut self, value: &Value<'_>, key: &str) -> Parsed<bool> {
        value
            .as_bool()
            .ok_or_else(|| self.wrong_type(value, key, "`true` or `false`"))
    }

    /// A string, with its span (quotes included).
    pub(super) fn string<'t>(
        &mut self,
        value: &'t Value<'_>,
        key: &str,
    ) -> Parsed<(&'t str, Span)> {
        match value.as_str() {
            Some(text) => Ok((text, self.span_of(value))),
            None => Err(self.wrong_type(value, key, "a string")),
        }
    }

    /// An array of exactly `N` numbers, each checked by `check`.
    pub(super) fn numbers<const N: usize>(
        &mut self,
        value: &Value<'_>,
        key: &str,
        check: fn(&mut Self, &Value<'_>, &str) -> Parsed<f64>,
    ) -> Parsed<[f64; N]> {
        let items = self.array(value, key, &format!("an array of {N} numbers"))?;
        if items.len() != N {
            return Err(self.error(
                value.span,
                format!("expected {N} numbers for `{key}`, found {}", items.len()),
            ));
        }
        let numbers = all(items.iter().map(|item| check(self, item, key)))?;
        let mut array = [0.0; N];
        array.copy_from_slice(&numbers);
        Ok(array)
    }

    /// A point or vector `[x, y, z]`, each number within
    /// ±[`magnitude::MAX_COORDINATE`].
    pub(super) fn vec3(&mut self, value: &Value<'_>, key: &str) -> Parsed<Vec3> {
        self.numbers::<3>(value, key, Self::coordinate)
            .map(Vec3::from_array)
    }

    /// A finite number within ±[`magnitude::MAX_COORDINATE`].
    pub(super) fn coordinate(&mut self, value: &Value<'_>, key: &str) -> Parsed<f64> {
        let number = self.number(value, key)?;
        magnitude::coordinate(number).map_err(|error| self.out_of_range(value, key, error))
    }

    /// A list of points `[[x, y, z], ...]`.
    pub(super) fn points(&mut self, value: &Value<'_>, key: &str) -> Parsed<Vec<Vec3>> {
        let items = self.array(value, key, "a list of points [[x, y, z], ...]")?;
        all(items.iter().map(|item| self.vec3(item, key)))
    }

    /// A non-zero vector `[x, y, z]`, normalised. Only `[0, 0, 0]` is
    /// refused: however short or long, any other vector has a direction.
    pub(super) fn direction(&mut self, value: &Value<'_>, key: &str) -> Parsed<Vec3> {
        let v = Vec3::from_array(self.numbers::<3>(value, key, Self::number)?);
        unit(v)
            .ok_or_else(|| self.error(value.span, format!("`{key}` must not be the zero vector")))
    }

    /// A factor of radiance: a number `>= 0` and at most
    /// [`factor::MAX_FACTOR`].
    pub(super) fn factor(&mut self, value: &Value<'_>, key: &str) -> Parsed<f64> {
        let number = self.non_negative(value, key)?;
        factor::factor(number).map_err(|error| self.out_of_range(value, key, error))
    }

    /// A number that divides radiance: `0`, or positive within
    /// [`factor::divisor`]'s range.
    pub(super) fn divisor(&mut self, value: &Value<'_>, key: &str) -> Parsed<f64> {
        let number = self.non_negative(value, key)?;
        factor::divisor(number).map_err(|error| self.out_of_range(value, key, error))
    }

    /// Records "`key` is out of range: `error`" at `value`.
    fn out_of_range(
        &mut self,
        value: &Value<'_>,
        key: &str,
        error: impl std::fmt::Display,
    ) -> Reported {
        self.error(value.span, format!("`{key}` is out of range: {error}"))
    }

    /// A colour: `[r, g, b]` or one number for a grey, never negative, each
    /// component a [`Reader::factor`].
    pub(super) fn color(&mut self, value: &Value<'_>, key: &str) -> Parsed<Color> {
        if value.as_array().is_some() {
            self.numbers::<3>(value, key, Self::factor).map(Color::from)
        } else if value.as_integer().is_some() || value.as_float().is_some() {
            self.factor(value, key).map(Color::splat)
        } else {
            Err(self.wrong_type(value, key, "a colour ([r, g, b] or a number)"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads the value of `x` in `source` with `read`; the messages on error.
    fn read<'s, T>(
        source: &'s str,
        read: impl FnOnce(&mut Reader<'s>, &Value<'s>, &str) -> Parsed<T>,
    ) -> Result<T, Vec<String>> {
        let root = toml_span::parse(source).unwrap();
        let mut reader = Reader::new(source, Path::new("t.toml"));
        let value = read(&mut reader, root.pointer("/x").unwrap(), "x");
        reader
            .finish_with_warnings(value)
            .map(|(value, _)| value)
            .map_err(|e| match e {
                SceneError::Invalid { diagnostics } => {
                    diagnostics.into_iter().map(|d| d.message).collect()
                }
                other => panic!("{other}"),
            })
    }

    #[test]
    fn numbers_accept_integers_and_floats_but_not_nan_or_strings() {
        assert_eq!(read("x = 3", Reader::number), Ok(3.0));
        assert_eq!(read("x = -2.5e1", Reader::number), Ok(-25.0));
        assert_eq!(
            read("x = nan", Reader::number),
            Err(vec!["expected a finite number for `x`, found NaN".into()])
        );
        assert_eq!(
            read("x = '3'", Reader::number),
            Err(vec!["expected a number for `x`, found a string".into()])
        );
    }

    #[test]
    fn ranges_are_checked() {
        assert_eq!(read("x = 0", Reader::non_negative), Ok(0.0));
        assert_eq!(
            read("x = -1", Reader::non_negative),
            Err(vec!["`x` must not be negative, got -1".into()])
        );
        assert_eq!(
            read("x = 0", Reader::positive),
            Err(vec!["`x` must be greater than 0, got 0".into()])
        );
        let count = |r: &mut Reader<'_>, v: &Value<'_>, k: &str| r.count(v, k, 1, 9);
        assert_eq!(read("x = 7", count), Ok(7));
        assert_eq!(read("x = 9", count), Ok(9));
        assert_eq!(
            read("x = 10", count),
            Err(vec!["`x` must be at most 9, got 10".into()])
        );
        assert_eq!(
            read("x = 0", count),
            Err(vec!["`x` must be at least 1, got 0".into()])
        );
        assert_eq!(
            read("x = 5000000000", count),
            Err(vec!["`x` must be at most 9, got 5000000000".into()])
        );
        assert_eq!(
            read("x = 1.5", count),
            Err(vec!["expected an integer for `x`, found a float".into()])
        );
    }

    #[test]
    fn vectors_report_every_bad_component() {
        assert_eq!(
            read("x = [1, 2.5, -3]", Reader::vec3),
            Ok(Vec3::new(1.0, 2.5, -3.0))
        );
        assert_eq!(
            read("x = [1, 2]", Reader::vec3),
            Err(vec!["expected 3 numbers for `x`, found 2".into()])
        );
        assert_eq!(
            read("x = ['a', 2, true]", Reader::vec3),
            Err(vec![
                "expected a number for `x`, found a string".into(),
                "expected a number for `x`, found a boolean".into()
            ])
        );
        assert_eq!(
            read("x = 1", Reader::vec3),
            Err(vec![
                "expected an array of 3 numbers for `x`, found an integer".into()
            ])
        );
        assert_eq!(read("x = [0, 0, 2]", Reader::direction), Ok(Vec3::Z));
        assert_eq!(read("x = [1e-200, 0, 0]", Reader::direction), Ok(Vec3::X));
        assert_eq!(read("x = [0, -1e200, 0]", Reader::direction), Ok(-Vec3::Y));
        assert_eq!(read("x = [0, 0, -5e-324]", Reader::direction), Ok(-Vec3::Z));
        assert_eq!(
            read("x = [0, 0, 0]", Reader::direction),
            Err(vec!["`x` must not be the zero vector".into()])
        );
    }

    #[test]
    fn colours_are_triples_or_greys_and_never_negative() {
        assert_eq!(
            read("x = [1, 0.5, 0]", Reader::color),
            Ok(Color::new(1.0, 0.5, 0.0))
        );
        assert_eq!(read("x = 0.25", Reader::color), Ok(Color::splat(0.25)));
        assert_eq!(
            read("x = [1, -1, 0]", Reader::color),
            Err(vec!["`x` must not be negative, got -1".into()])
        );
        assert_eq!(
            read("x = 'red'", Reader::color),
            Err(vec![
                "expected a colour ([r, g, b] or a number) for `x`, found a string".into()
            ])
        );
    }

    #[test]
    fn string_spans_include_their_quotes() {
        for (source, quoted) in [
            ("x = \"ab\"", "\"ab\""),
            ("x = 'ab'", "'ab'"),
            ("x = \"\"\"ab\"\"\"", "\"\"\"ab\"\"\""),
        ] {
            let (text, span) = read(source, |r, v, k| {
                r.string(v, k).map(|(text, span)| (text.to_string(), span))
            })
            .unwrap();
            assert_eq!(text, "ab");
            assert_eq!(&source[span.start..span.end], quoted);
        }
    }
}
