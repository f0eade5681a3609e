//! Whole files: entities together, the scene they make, and recovery from
//! errors.

use super::*;
use crate::scene::{Diagnostic, Severity};
use crate::shape::Shape;

/// A view block, to put in front of a test's own entities.
const VIEW: &str = "v\nfrom 0 -5 0\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\nresolution 32 24\n";

fn scene(source: &str) -> Scene {
    match parse_nff(source, Path::new("t.nff")) {
        Ok(scene) => scene,
        Err(error) => panic!("{error}"),
    }
}

/// `line:column: message` of every error in `source`.
fn errors(source: &str) -> Vec<String> {
    match parse_nff(source, Path::new("t.nff")) {
        Ok(_) => panic!("no error in:\n{source}"),
        Err(SceneError::Invalid { diagnostics }) => diagnostics
            .into_iter()
            .map(|d| format!("{}:{}: {}", d.line, d.column, d.message))
            .collect(),
        Err(error) => panic!("{error}"),
    }
}

#[test]
fn the_view_sets_camera_size_and_the_spd_tracing_rules() {
    let s = scene(VIEW);
    assert_eq!(s.camera.eye(), Vec3::new(0.0, -5.0, 0.0));
    assert_eq!(s.camera.up(), Vec3::Z);
    assert_eq!(s.camera.fov_degrees(), view::edge_to_edge_fov(45.0, 24));
    assert_eq!((s.settings.width, s.settings.height), (32, 24));
    assert_eq!((s.settings.max_depth, s.settings.min_weight), (4, 0.0));
    assert_eq!(s.background, Color::ZERO);
    assert_eq!(s.ambient, Color::splat(AMBIENT));
    assert!(s.objects.primitives.is_empty() && s.lights.is_empty());
}

#[test]
fn nff_colours_are_display_values() {
    assert_eq!(scene(VIEW).color_space, ColorSpace::Display);
}

#[test]
fn lights_without_a_colour_share_one_over_root_n() {
    let s = scene(&format!(
        "b 0.1 0.2 0.3\n{VIEW}l 1 2 3\nl 4 5 6 0.5 0.25 1\nl 0 0 9\nl 1 1 1\n"
    ));
    assert_eq!(s.background, Color::new(0.1, 0.2, 0.3));
    let intensities: Vec<Color> = s
        .lights
        .iter()
        .map(|light| match light {
            Light::Point { intensity, .. } => *intensity,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(
        intensities,
        [
            Color::splat(0.5),
            Color::new(0.5, 0.25, 1.0),
            Color::splat(0.5),
            Color::splat(0.5)
        ]
    );
    let Light::Point { position, .. } = &s.lights[1] else {
        unreachable!()
    };
    assert_eq!(*position, Vec3::new(4.0, 5.0, 6.0));
}

#[test]
fn each_object_takes_the_material_of_the_last_fill_and_repeats_share_one() {
    let s = scene(&format!(
        "{VIEW}s 0 0 0 1\nf 1 0 0 1 0 0 0 0\ns 0 0 0 1\nf 0 1 0 1 0 0 0 0\n\
         c 0 0 0 1 0 0 1 1\nf 1 0 0 1 0 0 0 0\np 3 0 0 0 1 0 0 0 1 0\n"
    ));
    let materials: Vec<u32> = s.objects.primitives.iter().map(|p| p.material.0).collect();
    // The first sphere, before any `f`, gets the default grey.
    assert_eq!(materials, [0, 1, 2, 1]);
    assert_eq!(s.materials.len(), 3);
    assert_eq!(s.materials[0], Material::default());
    assert_eq!(s.materials[1].diffuse, Color::new(1.0, 0.0, 0.0).into());
}

#[test]
fn every_entity_is_read_and_patches_follow_the_other_shapes() {
    let s = scene(&format!(
        "{VIEW}f 1 1 1 1 0 0 0 0\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n\
         s 0 0 0 1 # a comment\nc\n0 0 0 1\n0 0 1 0.5\n\
         p 5 0 0 0 2 0 0 2 2 0 1 1 0 0 2 0\n"
    ));
    let kinds: Vec<&str> = s
        .objects
        .primitives
        .iter()
        .map(|p| p.shape.kind())
        .collect();
    assert_eq!(kinds, ["sphere", "cone", "polygon"]);
    assert_eq!(s.objects.meshes.len(), 1);
    assert_eq!(s.objects.meshes[0].len(), 1);
    assert_eq!(s.objects.primitive_count(), 4);
    let cone = &s.objects.primitives[1];
    let placement = cone.transform.map_or(Transform::IDENTITY, |id| {
        s.objects.transforms[id.0 as usize]
    });
    let apex = placement.point_to_world(Vec3::new(0.0, 0.0, 1.0));
    assert!(apex.abs_diff_eq(Vec3::Z, 1e-15));
    assert!(matches!(cone.shape, Shape::Cone(c) if !c.caps()));
}

#[test]
fn every_error_is_reported_and_reading_resumes_at_the_next_entity() {
    assert_eq!(
        errors(&format!(
            "{VIEW}s 0 0 0 abc\ns 0 0 0 1\nq 1 2\nf 1 1 1 1 0 0 0\nl 1 2 3\n\
             p 3 0 0 0 1 0 0 0 1 0 5\ns 1 1\n"
        )),
        [
            "8:9: expected a number for the sphere's radius, found `abc`",
            "10:1: unknown entity `q`; expected one of: v, b, l, f, c, s, p, pp (or a # comment)",
            "12:1: expected a number for the material's index of refraction, found `l`",
            "13:23: expected an entity keyword (v, b, l, f, c, s, p, pp), found the number `5`: \
             too many numbers for the entity before it?",
            "14:6: expected a number for the sphere's centre, found the end of the file",
        ]
    );
}

#[test]
fn the_view_is_required_once_and_checked() {
    assert_eq!(
        errors("s 0 0 0 1\n"),
        ["1:1: the file has no view `v`: an NFF scene needs one"]
    );
    assert_eq!(
        errors(""),
        ["1:1: the file has no view `v`: an NFF scene needs one"]
    );
    assert_eq!(
        errors(&format!("{VIEW}{VIEW}")),
        ["8:1: a second view `v`: a file has only one"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 0 0 0\nup 0 0 1\nangle 45\nhither 1\nresolution 8 8\n"),
        ["3:4: the view's `from` and `at` are the same point"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 2 0 0\nangle 45\nhither 1\nresolution 8 8\n"),
        ["4:4: the view's `up` is zero or parallel to the view direction"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 0 0 1\nangle 180\nhither 1\nresolution 8 8\n"),
        ["5:7: the view's `angle` must be between 0 and 180 degrees, got 180"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nangle 45\nhither 1\nresolution 8 8\n"),
        ["4:1: expected `up` in the view, found `angle`"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 1 0 0\nangle 45\nhither -1\nresolution 0 8\n"),
        ["6:8: the view's `hither` must not be negative, got -1"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 1 0 0\nangle 45\nhither 1\nresolution 0 8\n"),
        ["7:12: the view's resolution (width) must be at least 1, got 0"]
    );
}

#[test]
fn numbers_out_of_range_are_called_so_however_many_digits_they_have() {
    let view = |resolution: &str| {
        format!("v\nfrom 0 0 0\nat 1 0 0\nup 0 0 1\nangle 45\nhither 1\nresolution {resolution}\n")
    };
    assert_eq!(
        errors(&view("-1 8")),
        ["7:12: the view's resolution (width) must be at least 1, got -1"]
    );
    assert_eq!(
        errors(&view("8 99999999999999999999")),
        ["7:14: the view's resolution (height) must be at most 65535, got 99999999999999999999"]
    );
    assert_eq!(
        errors(&view("65535 65535")),
        [
            "7:12: the view's resolution: the image 65535x65535 is too large: at most 268435456 \
             pixels are allowed"
        ]
    );
    assert_eq!(
        errors(&format!("{VIEW}p 18446744073709551615\n")),
        ["8:3: the polygon's vertex count must be at most 4294967295, got 18446744073709551615"]
    );
}

#[test]
fn a_degenerate_patch_is_refused_at_its_place() {
    assert_eq!(
        errors(&format!(
            "{VIEW}pp 3 0 0 0 0 0 1 1 1 1 0 0 1 2 2 2 0 0 1\ns 0 0 0 0\n"
        )),
        [
            "8:1: degenerate triangle: its vertices are collinear or coincide",
            "9:1: radius must be a positive number, got 0",
        ]
    );
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let error = load_nff(Path::new("/nonexistent/scene.nff")).unwrap_err();
    assert!(matches!(error, SceneError::Io { .. }));
    assert!(error.to_string().contains("/nonexistent/scene.nff"));
}

/// The fixture every entity of which the truncation and mangling tests cut
/// or spoil.
const SPD_LIKE: &str = include_str!("../../../tests/nff/spd_like.nff");

/// The byte ranges of the words of `source`, `#` comments left out (a
/// scanner of its own, so that the tests do not trust the lexer they test).
fn word_spans(source: &str) -> Vec<Range<usize>> {
    let mut spans = Vec::new();
    let mut start = None;
    let mut in_comment = false;
    for (i, c) in source.char_indices().chain([(source.len(), '\n')]) {
        if in_comment {
            in_comment = c != '\n';
            continue;
        }
        if c.is_ascii_whitespace() || c == '#' {
            if let Some(s) = start.take() {
                spans.push(s..i);
            }
            in_comment = c == '#';
        } else if start.is_none() {
            start = Some(i);
        }
    }
    spans
}

/// The text of the line `end` is on, from its start to `end`.
fn line_before(source: &str, end: usize) -> &str {
    &source[source[..end].rfind('\n').map_or(0, |i| i + 1)..end]
}

/// Checks that `result`, from reading `source` as `t.nff`, is an error
/// whose every diagnostic is an error located in the file: `t.nff:L:C:`
/// with line `L` and column `C` a place in `source` (up to just after its
/// last character). Returns the diagnostics.
fn located_errors(result: Result<Scene, SceneError>, source: &str) -> Vec<Diagnostic> {
    let diagnostics = match result {
        Ok(_) => panic!("no error in:\n{source}"),
        Err(SceneError::Invalid { diagnostics }) => diagnostics,
        Err(error) => panic!("not a located error: {error}\nin:\n{source}"),
    };
    assert!(
        !diagnostics.is_empty(),
        "an error without diagnostics in:\n{source}"
    );
    let lines: Vec<&str> = source.split('\n').collect();
    for d in &diagnostics {
        assert_eq!(d.severity, Severity::Error, "{d}");
        assert_eq!(d.path, Path::new("t.nff"), "{d}");
        let line = lines
            .get(d.line.wrapping_sub(1))
            .unwrap_or_else(|| panic!("line {} is not in the file: {d}\nin:\n{source}", d.line));
        assert!(
            (1..=line.chars().count() + 1).contains(&d.column),
            "column {} is not on line {}: {d}\nin:\n{source}",
            d.column,
            d.line
        );
        let shown = d.to_string();
        let place = format!("t.nff:{}:{}: error: ", d.line, d.column);
        assert!(shown.starts_with(&place), "{shown}");
    }
    diagnostics
}

/// Cuts inside the last number of an entity that still leave a valid file:
/// the digits left are a number the entity accepts.
const CUT_NUMBERS_ACCEPTED: &[&str] = &[
    // A 64 x 4 picture.
    "resolution 64 4",
    // The second light's blue: 0, 0 and 0.2 are colours.
    "l -4 -2 5 0.3 0.3 0",
    "l -4 -2 5 0.3 0.3 0.",
    "l -4 -2 5 0.3 0.3 0.2",
    // A cone's apex radius of 0: a pointed cone.
    "1.5 0 1.5 0",
    "1.5 0 1.5 0.",
    "c -1.5 0 0 0.3 -1.5 0 1.5 0",
    "c -1.5 0 0 0.3 -1.5 0 1.5 0.",
    // An index of refraction of 1.
    "f 1 1 1 0.1 0.1 101.148 0.9 1",
    "f 1 1 1 0.1 0.1 101.148 0.9 1.",
];

/// Cuts inside the last number of an entity that leave an invalid one, with
/// the error each gives.
const CUT_NUMBERS_REFUSED: &[(&str, &str)] = &[
    ("s 0 0 1 0", "radius must be a positive number, got 0"),
    ("s 0 0 1 0.", "radius must be a positive number, got 0"),
    (
        "s -0.6 -1.6 0.5 0",
        "radius must be a positive number, got 0",
    ),
    (
        "s -0.6 -1.6 0.5 0.",
        "radius must be a positive number, got 0",
    ),
];

/// The hexagon with its last `z` of 0.01 cut.
const HEXAGON: &str = "p 6 2 -2 0.01 3 -2 0.01 3 -1 0.01 2.5 -1.5 0.01 2 -1 0.01 2.2 -1.5 ";

#[test]
fn every_truncation_gives_located_errors_unless_it_ends_a_whole_entity() {
    let source = SPD_LIKE;
    let words = word_spans(source);
    let text = |i: usize| &source[words[i].clone()];
    // A word ends an entity when an entity keyword or the end of the file
    // follows it, or when it ends a light's position (its colour may be
    // left out). Only entities after the whole view can end a valid file.
    let view_end = (0..words.len())
        .position(|i| text(i) == "resolution")
        .unwrap()
        + 2;
    let ends_entity = |i: usize| {
        i >= view_end
            && (i + 1 == words.len()
                || ENTITY_KEYWORDS.contains(&text(i + 1))
                || (i >= 3 && text(i - 3) == "l"))
    };
    let mut accepted_cuts = Vec::new();
    let mut valid_prefixes = 0;
    for end in (0..=source.len()).filter(|&end| source.is_char_boundary(end)) {
        let prefix = &source[..end];
        let result = parse_nff(prefix, Path::new("t.nff"));
        // The last word that starts before the cut, and whether it is cut.
        let last = words.iter().rposition(|w| w.start < end);
        let cut_inside = last.is_some_and(|i| words[i].end > end);
        let whole_entity = last.is_some_and(|i| ends_entity(i) && !cut_inside);
        let line = line_before(source, end);
        if whole_entity {
            assert!(
                result.is_ok(),
                "{:?} ends an entity, but: {}",
                line,
                result.unwrap_err()
            );
            valid_prefixes += 1;
        } else if last.is_some_and(|i| cut_inside && ends_entity(i)) {
            if CUT_NUMBERS_ACCEPTED.contains(&line) {
                assert!(result.is_ok(), "{line:?}: {}", result.unwrap_err());
                accepted_cuts.push(line);
                continue;
            }
            let errors = located_errors(result, prefix);
            let expected = match CUT_NUMBERS_REFUSED.iter().find(|(cut, _)| *cut == line) {
                Some((_, message)) => message.to_string(),
                // 0 puts the last vertex off the plane z = 0.01 of the others.
                None if [HEXAGON, "0"].concat() == line
                    || [HEXAGON, "0."].concat() == line
                    || [HEXAGON, "0.0"].concat() == line =>
                {
                    "the polygon is not planar: vertex".to_string()
                }
                None => panic!("a cut number not classified: {line:?} gives {errors:?}"),
            };
            assert!(
                errors.iter().any(|d| d.message.contains(&expected)),
                "{line:?}: expected `{expected}`, got {errors:?}"
            );
        } else {
            // Cut inside an entity, or before the view is whole: an error,
            // located no later than the cut.
            let errors = located_errors(result, prefix);
            let (line_count, column) = (
                prefix.matches('\n').count() + 1,
                line_before(source, end).chars().count() + 1,
            );
            let last_error = errors.last().unwrap();
            assert!(
                (last_error.line, last_error.column) <= (line_count, column),
                "{last_error} lies after the cut at {line_count}:{column}"
            );
        }
    }
    // Every accepted cut was met: the table says no more than the file has.
    assert_eq!(accepted_cuts, CUT_NUMBERS_ACCEPTED);
    // The view and the 13 entities after it, each just after its last
    // word and after the line break that follows it; and the second light
    // cut after its position, before and after the space that follows.
    assert_eq!(valid_prefixes, 2 * 14 + 2);
}

#[test]
fn a_spoiled_word_gives_an_error_at_that_word() {
    let source = SPD_LIKE;
    let words = word_spans(source);
    // Words no entity reads at any place: not a number, not finite, or not
    // a word of the format; each must be reported where it stands.
    for bad in ["x", "é", "nan", "1e999", "-inf"] {
        for span in &words {
            let spoiled = format!("{}{bad}{}", &source[..span.start], &source[span.end..]);
            let errors = located_errors(parse_nff(&spoiled, Path::new("t.nff")), &spoiled);
            let line = source[..span.start].matches('\n').count() + 1;
            let column = line_before(source, span.start).chars().count() + 1;
            assert!(
                errors.iter().any(|d| (d.line, d.column) == (line, column)),
                "`{bad}` in place of `{}` at {line}:{column}: {errors:?}",
                &source[span.clone()]
            );
        }
    }
}

#[test]
fn a_keyword_in_place_of_any_word_gives_located_errors() {
    let source = SPD_LIKE;
    // Where a number belongs, a keyword cuts the entity short; in place of a
    // keyword, the numbers that follow do not make the new entity (`p` and
    // `pp` need a count then three or six numbers per vertex, none of the
    // file's entities has that shape).
    for keyword in ["p", "pp", "v"] {
        for span in word_spans(source) {
            if &source[span.clone()] == keyword {
                continue;
            }
            let spoiled = format!("{}{keyword}{}", &source[..span.start], &source[span.end..]);
            located_errors(parse_nff(&spoiled, Path::new("t.nff")), &spoiled);
        }
    }
}

#[test]
fn plausible_words_anywhere_give_a_scene_or_located_errors_never_a_panic() {
    let source = SPD_LIKE;
    // Words that some entities accept at some places; `#` comments out the
    // rest of its line.
    for word in ["-1", "0", "99999999999", "#"] {
        let (mut scenes, mut refused) = (0, 0);
        for span in word_spans(source) {
            let spoiled = format!("{}{word}{}", &source[..span.start], &source[span.end..]);
            match parse_nff(&spoiled, Path::new("t.nff")) {
                Ok(_) => scenes += 1,
                result => {
                    located_errors(result, &spoiled);
                    refused += 1;
                }
            }
        }
        // Both answers occur: the word is neither always right nor always
        // wrong, so both branches above were checked.
        assert!(
            scenes > 0 && refused > 0,
            "`{word}`: {scenes} scenes, {refused} refused"
        );
    }
}
