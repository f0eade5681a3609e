//! The `bezier_patch` shape in the TOML format: read, placed and refused
//! with located errors.

use std::path::Path;

use whitted::math::Vec3;
use whitted::scene::{SceneError, parse_scene};
use whitted::shape::{BezierPatch, Shape};

const CAMERA: &str = "[camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\n";

const SADDLE: &str = "[[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]], \
    [[1, 0, 0], [1, 1, 1], [1, 2, 2], [1, 3, 3]], \
    [[2, 0, 0], [2, 1, 2], [2, 2, 4], [2, 3, 6]], \
    [[3, 0, 0], [3, 1, 3], [3, 2, 6], [3, 3, 9]]";

/// The messages and (line, column) of every error in `source`.
fn errors(source: &str) -> Vec<(String, usize, usize)> {
    match parse_scene(source, Path::new("t.toml")) {
        Err(SceneError::Invalid { diagnostics }) => diagnostics
            .into_iter()
            .map(|d| (d.message, d.line, d.column))
            .collect(),
        other => panic!("not refused: {other:?}"),
    }
}

#[test]
fn a_patch_is_read_row_by_row() {
    let source = format!("{CAMERA}[[objects]]\nshape = 'bezier_patch'\npoints = [{SADDLE}]\n");
    let scene = parse_scene(&source, Path::new("t.toml")).unwrap();
    let expected = BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| Vec3::new(i as f64, j as f64, (i * j) as f64))
    }))
    .unwrap();
    assert_eq!(
        scene.objects.primitives[0].shape,
        Shape::BezierPatch(expected)
    );
}

#[test]
fn bad_nets_are_refused_where_they_are_wrong() {
    let source = format!(
        "{CAMERA}[[objects]]\nshape = 'bezier_patch'\npoints = [[[0, 0, 0]]]\n\
         [[objects]]\nshape = 'bezier_patch'\npoints = [{SADDLE}, {SADDLE}]\n\
         [[objects]]\nshape = 'bezier_patch'\npoints = [[[1, 1, 1], [1, 1, 1], [1, 1, 1], [1, 1, 1]], \
         [[1, 1, 1], [1, 1, 1], [1, 1, 1], [1, 1, 1]], [[1, 1, 1], [1, 1, 1], [1, 1, 1], [1, 1, 1]], \
         [[1, 1, 1], [1, 1, 1], [1, 1, 1], [1, 1, 1]]]\n\
         [[objects]]\nshape = 'bezier_patch'\npoints = [[[0, 0, nan], [0, 1, 0], [0, 2, 0], [0, 3, 0]]]\n\
         [[objects]]\nshape = 'bezier_patch'\n"
    );
    let found = errors(&source);
    let messages: Vec<&str> = found.iter().map(|(m, _, _)| m.as_str()).collect();
    assert_eq!(
        messages,
        [
            "expected 4 points in each row of `points`, found 1",
            "expected 4 rows of 4 points for `points`, found 8 rows",
            "degenerate Bézier patch: all its control points are equal",
            "expected a finite number for `points`, found NaN",
            "missing required key `points` in object",
        ],
        "{found:?}"
    );
    assert_eq!((found[0].1, found[0].2), (6, 11));
    assert_eq!((found[1].1, found[1].2), (9, 10));
}
