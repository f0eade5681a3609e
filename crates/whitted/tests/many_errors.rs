//! A file with an error in every word is reported in time and space in
//! proportion to its size: each reader stops reporting after
//! `MAX_DIAGNOSTICS` errors (building a diagnostic costs time in proportion
//! to its place in the file), and a diagnostic shows only part of a very
//! long line. Before these limits, 80 KB of `s s s ...` in NFF took a minute
//! and gave a 4.8 GB message.

use std::path::Path;

use whitted::bench::obj_positions::parse_obj_positions;
use whitted::scene::{MAX_DIAGNOSTICS, SceneError, parse_nff, parse_obj, parse_scene};

/// The diagnostics' count and the whole message's length, and checks the
/// last diagnostic says reporting stopped.
fn reported(result: Result<(), SceneError>) -> (usize, usize) {
    let Err(error) = result else {
        panic!("accepted a file full of errors");
    };
    let message = error.to_string();
    let SceneError::Invalid { diagnostics } = error else {
        panic!("not an Invalid error: {message}");
    };
    let last = diagnostics.last().expect("at least one diagnostic");
    assert!(
        last.message
            .starts_with("too many errors: the first 100 are reported"),
        "{}",
        last.message
    );
    (diagnostics.len(), message.len())
}

/// The most a report may take: every diagnostic with a line cut to about
/// 160 characters and a message of about as many.
const MAX_MESSAGE: usize = (MAX_DIAGNOSTICS + 1) * 600;

#[test]
fn nff_with_an_error_in_every_word_on_one_line() {
    let source = "s ".repeat(200_000);
    let (count, length) = reported(parse_nff(&source, Path::new("a.nff")).map(drop));
    assert_eq!(count, MAX_DIAGNOSTICS + 1);
    assert!(length < MAX_MESSAGE, "{length}");
}

#[test]
fn toml_with_an_error_in_every_object() {
    let source = "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\n".to_string()
        + &"[[objects]]\nshape = \"sphere\"\nradius = -1\n".repeat(50_000);
    let (count, length) = reported(parse_scene(&source, Path::new("a.toml")).map(drop));
    assert_eq!(count, MAX_DIAGNOSTICS + 1);
    assert!(length < MAX_MESSAGE, "{length}");
}

#[test]
fn obj_with_an_error_in_every_line() {
    let source = "v 0 0 0\n".to_string() + &"f 1 2 x\n".repeat(100_000);
    let (count, length) = reported(parse_obj(&source, Path::new("a.obj")).map(drop));
    assert_eq!(count, MAX_DIAGNOSTICS + 1);
    assert!(length < MAX_MESSAGE, "{length}");
    let (count, _) = reported(parse_obj_positions(&source, Path::new("a.obj")).map(drop));
    assert_eq!(count, MAX_DIAGNOSTICS + 1);
}

#[test]
fn mtl_with_an_error_in_every_line() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(
        folder.path().join("a.mtl"),
        "newmtl a\n".to_string() + &"Kd x\n".repeat(100_000),
    )
    .unwrap();
    let model = "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let result = parse_obj(model, &folder.path().join("a.obj")).map(drop);
    let (count, length) = reported(result);
    assert_eq!(count, MAX_DIAGNOSTICS + 1);
    assert!(length < MAX_MESSAGE, "{length}");
}
