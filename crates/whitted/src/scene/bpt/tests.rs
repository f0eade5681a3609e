use super::*;

/// The saddle z = xy as one patch.
const SADDLE: &str = "1\n3 3\n\
    0 0 0  0 0.333 0  0 0.667 0  0 1 0\n\
    0.333 0 0  0.333 0.333 0.111  0.333 0.667 0.222  0.333 1 0.333\n\
    0.667 0 0  0.667 0.333 0.222  0.667 0.667 0.444  0.667 1 0.667\n\
    1 0 0  1 0.333 0.333  1 0.667 0.667  1 1 1\n";

fn messages(source: &str) -> Vec<String> {
    match parse_bpt_patches(source, Path::new("t.bpt")) {
        Err(SceneError::Invalid { diagnostics }) => diagnostics
            .iter()
            .map(|d| format!("{}:{}: {}", d.line, d.column, d.message))
            .collect(),
        other => panic!("accepted: {other:?}"),
    }
}

#[test]
fn a_patch_is_read_row_by_row() {
    let patches = parse_bpt_patches(SADDLE, Path::new("t.bpt")).unwrap();
    assert_eq!(patches.len(), 1);
    assert_eq!(patches[0].points()[1][2], Vec3::new(0.333, 0.667, 0.222));
    assert_eq!(patches[0].points()[3][3], Vec3::ONE);
}

#[test]
fn the_teapot_is_read_and_framed_upright() {
    let text = include_str!("../../../../../scenes/teapot.bpt");
    let patches = parse_bpt_patches(text, Path::new("teapot.bpt")).unwrap();
    assert_eq!(patches.len(), 32);
    let loaded = parse_bpt(text, Path::new("teapot.bpt")).unwrap();
    // Each patch is its pieces, whose boxes are widened for rounding.
    let pieces: usize = patches.iter().map(|p| p.pieces().count()).sum();
    assert!(pieces >= 32 * 16);
    assert_eq!(loaded.scene.objects.primitives.len(), pieces);
    let bounds = loaded
        .scene
        .objects
        .primitives
        .iter()
        .fold(Aabb::EMPTY, |b, p| b.union(&p.shape.bounds()));
    assert!((bounds.min.y - 0.0).abs() < 1e-8 && (bounds.max.y - 3.15).abs() < 1e-8);
}

#[test]
fn errors_are_located() {
    assert_eq!(
        messages("2\n3 3\n1 2 x"),
        ["3:5: expected a number for point 1 of patch 1, found `x`"]
    );
    assert_eq!(
        messages("1\n2 3\n"),
        ["2:1: patch 1 has degrees 2 3; only bicubic patches (3 3) are read"]
    );
    assert_eq!(
        messages("1\n3 3\n0 0 0"),
        ["3:6: the file ends where point 2 of patch 1 was expected"]
    );
    let flat = format!("1\n3 3\n{}", "1 1 1\n".repeat(16));
    assert_eq!(
        messages(&flat),
        ["2:1: patch 1: degenerate Bézier patch: all its control points are equal"]
    );
    assert_eq!(
        messages(&format!("{SADDLE}7")),
        ["7:1: expected the end of the file after 1 patches"]
    );
    assert_eq!(
        messages("1\n3 3\n1e31"),
        [
            "3:1: point 1 of patch 1 is out of range: 1e31 is too large: at most 1e30 in magnitude is allowed"
        ]
    );
    assert_eq!(messages("-1").len(), 1);
}
