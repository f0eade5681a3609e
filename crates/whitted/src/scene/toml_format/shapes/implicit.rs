//! Reading `shape = "implicit"`: `function` (an expression), `bounds`
//! (two corners) and `max_gradient`.
//!
//! An error in the expression is reported at the very character of the
//! file it concerns: the string's span plus the offset in its text. A
//! literal string (`'...'`) and a basic string without escapes hold their
//! text as written; in a basic string with escapes the offset is mapped
//! through them (an escape that makes the character at fault is pointed at
//! its backslash); a multi-line string's first newline, which TOML drops,
//! is counted.

use toml_span::Span;
use toml_span::value::Value;

use super::super::reader::{Fields, Parsed, Reader};
use super::{Placed, measure, refused};
use crate::math::{Transform, Vec3};
use crate::shape::{Expression, Implicit, Shape, positive};

/// Reads an implicit surface.
pub(super) fn implicit(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let function = r.require(f, "function", read_function);
    let bounds = r.require(f, "bounds", |r, value, key| {
        let points = r.points(value, key)?;
        <[Vec3; 2]>::try_from(points).map_err(|points| {
            r.error(
                value.span,
                format!(
                    "expected 2 corners [[x0, y0, z0], [x1, y1, z1]] for `{key}`, found {}",
                    points.len()
                ),
            )
        })
    });
    let max_gradient = measure(r, f, "max_gradient", positive);
    let [min, max] = bounds?;
    let fallback = if f.get("bounds").is_some() {
        r.value_span(f, "bounds")
    } else {
        at
    };
    let shape = Implicit::new(function?, min, max, max_gradient?)
        .map_err(|e| refused(r, f, fallback, e))?;
    Ok(Placed {
        shape: Shape::Implicit(shape),
        placement: Transform::IDENTITY,
    })
}

/// The expression of `function`, compiled; an error at the character at
/// fault, or at the whole string when the function is a constant.
fn read_function(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Expression> {
    let (text, quoted) = r.string(value, key)?;
    let expression = Expression::parse(text).map_err(|error| {
        let raw = r.raw(value.span);
        let escapes = r.raw(quoted).starts_with('"');
        let offset = raw_offset(raw, text, error.offset, escapes);
        let span = offset.map_or(quoted, |offset| {
            let start = value.span.start + offset;
            let width = raw[offset..].chars().next().map_or(0, char::len_utf8);
            Span::new(start, start + width)
        });
        r.error(span, format!("in `{key}`: {}", error.message))
    })?;
    if expression.is_constant() {
        return Err(r.error(
            quoted,
            format!("`{key}` names none of x, y, z: it is a constant, not a surface"),
        ));
    }
    Ok(expression)
}

/// The byte in `raw` (a TOML string as written between its quotes) from
/// which byte `offset` of its value `decoded` comes; `escapes` for a basic
/// string. `None` when the walk does not end in `decoded`'s length (a form
/// not understood).
fn raw_offset(raw: &str, decoded: &str, offset: usize, escapes: bool) -> Option<usize> {
    if raw == decoded {
        return Some(offset);
    }
    // A multi-line string drops a newline right after its opening quotes.
    let mut i = if raw.starts_with("\r\n") && !decoded.starts_with("\r\n") {
        2
    } else if raw.starts_with('\n') && !decoded.starts_with('\n') {
        1
    } else {
        0
    };
    let bytes = raw.as_bytes();
    let mut d = 0;
    let mut found = None;
    while i < raw.len() {
        let c = raw[i..].chars().next()?;
        // The bytes this piece of `raw` takes, and the bytes it makes.
        let (taken, made) = if escapes && c == '\\' {
            let next = *bytes.get(i + 1)?;
            match next {
                b'u' | b'U' => {
                    let digits = if next == b'u' { 4 } else { 8 };
                    let hex = raw.get(i + 2..i + 2 + digits)?;
                    let code = u32::from_str_radix(hex, 16).ok()?;
                    (2 + digits, char::from_u32(code)?.len_utf8())
                }
                // A line-ending backslash: it and all whitespace after it,
                // newlines included, make nothing.
                b' ' | b'\t' | b'\r' | b'\n' => {
                    let blank = raw[i + 1..]
                        .bytes()
                        .take_while(|b| matches!(b, b' ' | b'\t' | b'\r' | b'\n'))
                        .count();
                    (1 + blank, 0)
                }
                _ => (2, 1),
            }
        } else {
            (c.len_utf8(), c.len_utf8())
        };
        if made > 0 && d == offset && found.is_none() {
            found = Some(i);
        }
        d += made;
        i += taken;
    }
    if d == offset && found.is_none() {
        found = Some(raw.len());
    }
    (d == decoded.len()).then_some(found?)
}

#[cfg(test)]
mod tests {
    use super::super::super::tests::{CAMERA, scene};
    use super::*;
    use crate::scene::SceneError;

    /// The diagnostics of `source` as (line, column, message).
    fn located(source: &str) -> Vec<(usize, usize, String)> {
        let Err(SceneError::Invalid { diagnostics }) =
            crate::scene::parse_scene(source, std::path::Path::new("t.toml"))
        else {
            panic!("the scene was accepted");
        };
        diagnostics
            .into_iter()
            .map(|d| (d.line, d.column, d.message))
            .collect()
    }

    fn object(keys: &str) -> String {
        format!("{CAMERA}[[objects]]\nshape = 'implicit'\n{keys}\n")
    }

    /// The line of the first key of `object`.
    const LINE: usize = 6;

    #[test]
    fn an_implicit_surface_is_read() {
        let s = scene(&object(
            "function = 'x^2 + y^2 + z^2 - 1'\nbounds = [[-1, -1, -1], [1, 1, 1]]\n\
             max_gradient = 3.5",
        ));
        let Shape::Implicit(shape) = &s.objects.primitives[0].shape else {
            panic!("not an implicit surface");
        };
        assert_eq!(shape.max_gradient(), 3.5);
        assert_eq!(shape.function().text(), "x^2 + y^2 + z^2 - 1");
        assert_eq!(shape.bounds().max, Vec3::ONE);
    }

    #[test]
    fn expression_errors_point_at_the_character_in_the_file() {
        let bounds = "bounds = [[-1, -1, -1], [1, 1, 1]]\nmax_gradient = 1";
        for (function, column) in [
            ("function = 'x + w'", 17),
            ("function = \"x + w\"", 17),
            ("function = \"\"\"x + w\"\"\"", 19),
            // \t decodes to one byte where two are written.
            ("function = \"x\\t+ w\"", 18),
            // \u0020 is one space written as six bytes.
            ("function = \"x\\u0020+ w\"", 22),
        ] {
            let errors = located(&object(&format!("{function}\n{bounds}")));
            assert_eq!(
                errors,
                [(
                    LINE,
                    column,
                    "in `function`: unknown variable `w`; expected x, y, z or pi".into()
                )],
                "{function}"
            );
        }
        // A multi-line string: the error's line and column in the file.
        let errors = located(&object(&format!(
            "function = '''\nx +\n  sin(y, z)'''\n{bounds}"
        )));
        assert_eq!(
            errors,
            [(
                LINE + 2,
                3,
                "in `function`: `sin` takes 1 argument, found 2".into()
            )]
        );
        // A line-ending backslash joins the lines.
        let errors = located(&object(&format!(
            "function = \"\"\"x + \\\n    foo(z)\"\"\"\n{bounds}"
        )));
        assert_eq!(errors.len(), 1);
        assert_eq!((errors[0].0, errors[0].1), (LINE + 1, 5), "{errors:?}");
    }

    #[test]
    fn degenerate_parameters_are_reported_at_their_values() {
        let errors = located(&format!(
            "{}{}{}{}{}",
            object("function = 'x'\nbounds = [[1, 1, 1], [-1, -1, -1]]\nmax_gradient = 1"),
            "[[objects]]\nshape = 'implicit'\nfunction = 'x'\n\
             bounds = [[0, 0, 0], [1, 0, 1]]\nmax_gradient = 0\n",
            "[[objects]]\nshape = 'implicit'\nfunction = '2 * pi'\n\
             bounds = [[0, 0, 0]]\nmax_gradient = -1\n",
            "[[objects]]\nshape = 'implicit'\nfunction = 'x'\n",
            "[[objects]]\nshape = 'implicit'\nfunction = ''\n\
             bounds = [[0, 0, 0], [1, 1, 1]]\nmax_gradient = 1\n",
        ));
        let messages: Vec<&str> = errors.iter().map(|e| e.2.as_str()).collect();
        assert_eq!(
            messages,
            [
                "degenerate implicit surface: the bounds' first corner must be below the \
                 second on every axis",
                "max_gradient must be a positive number, got 0",
                "`function` names none of x, y, z: it is a constant, not a surface",
                "expected 2 corners [[x0, y0, z0], [x1, y1, z1]] for `bounds`, found 1",
                "max_gradient must be a positive number, got -1",
                "missing required key `bounds` in object",
                "missing required key `max_gradient` in object",
                "in `function`: the expression is empty",
            ],
            "{errors:?}"
        );
        assert_eq!((errors[0].0, errors[0].1), (LINE + 1, 10));
        assert_eq!((errors[1].0, errors[1].1), (LINE + 7, 16));
    }
}
