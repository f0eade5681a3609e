//! Command-line arguments (issue 23, items 19 and 20): every value is
//! checked before the scene is read, and a refusal says its true cause.
//! Before, `--width 0` or `--threads 0` with a 5M-triangle OBJ was refused
//! only after 3.9 s and 864 MB of loading; `--width -1` got clap's "use
//! '-- -1'"; `--width 4294967296` was "not in 0..=4294967295"; `--spp
//! 4294967295` or `samples = 4294967295` rendered for hours; `bench --runs
//! 0` printed "best of 0 runs".

use std::io::{BufWriter, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use crate::support::{MIB, Probe, probe};

/// Writes a flat OBJ grid of `2 n²` triangles: 8.5 MB for `n = 400`
/// (320000 triangles). The old release binary refused `--width 0` or
/// `--threads 0` on it only after reading it: 0.45 s and 60 MB, where a
/// refusal before reading takes under 4 MB and no measurable time.
fn write_big_obj(path: &Path, n: u32) {
    let mut out = BufWriter::new(std::fs::File::create(path).unwrap());
    for i in 0..=n {
        for j in 0..=n {
            writeln!(out, "v {i} {j} {}", (i * 7 + j * 3) % 11).unwrap();
        }
    }
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j + 1;
            let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
            writeln!(out, "f {a} {b} {d}\nf {a} {d} {c}").unwrap();
        }
    }
    out.into_inner().unwrap().sync_all().unwrap();
}

/// Peak memory of a process that refused its arguments without reading
/// the scene (a debug build starts at about 6 MB).
const UNREAD_PEAK: u64 = 16 * MIB;

/// Runs `whitted args` and checks that it was refused with exit code
/// `code` and the message `says`, quickly, in little memory, writing
/// nothing.
fn assert_refused_early(args: &[&str], dir: &Path, code: i32, says: &str) -> Probe {
    let start = Instant::now();
    let p = probe(args, dir);
    let elapsed = start.elapsed();
    assert_eq!(p.code(), Some(code), "{args:?}: {}", p.stderr);
    assert!(p.stderr.contains(says), "{args:?}: {}", p.stderr);
    assert!(p.stdout.is_empty(), "{args:?}: {}", p.stdout);
    assert!(
        p.peak_bytes < UNREAD_PEAK,
        "{args:?}: peak {} MiB: the scene was read",
        p.peak_bytes / MIB
    );
    assert!(
        elapsed < Duration::from_millis(800),
        "{args:?}: {elapsed:?}"
    );
    assert!(!dir.join("out.png").exists(), "{args:?} wrote an image");
    p
}

#[test]
fn render_arguments_are_refused_before_a_big_scene_is_read_with_their_true_cause() {
    let dir = tempfile::tempdir().unwrap();
    write_big_obj(&dir.path().join("big.obj"), 400);
    let refused = |extra: &[&str], code, says: &str| {
        let args = [&["render", "big.obj", "-o", "out.png"][..], extra].concat();
        assert_refused_early(&args, dir.path(), code, says);
    };
    let invalid = |option: &str, value: &str, cause: &str| {
        format!("error: invalid value '{value}' for '{option}': {cause}")
    };
    for (option, value, cause) in [
        (
            "--width <W>",
            "0",
            "0 is less than 1; expected a whole number from 1 to 65535",
        ),
        (
            "--width <W>",
            "-1",
            "-1 is negative; expected a whole number from 1 to 65535",
        ),
        (
            "--height <H>",
            "4294967296",
            "4294967296 is more than 65535, the longest image side; \
             expected a whole number from 1 to 65535",
        ),
        (
            "--width <W>",
            "12.5",
            "12.5 is not a whole number; expected a whole number from 1 to 65535",
        ),
        (
            "--threads <T>",
            "0",
            "0 is less than 1; expected a whole number, at least 1",
        ),
        (
            "--threads <T>",
            "-1",
            "-1 is negative; expected a whole number, at least 1",
        ),
        (
            "--threads <T>",
            "many",
            "`many` is not a number; expected a whole number, at least 1",
        ),
        (
            "--spp <N>",
            "4294967295",
            "4294967295 is more than 65536, a 256x256 grid in each pixel, finer than an \
             8-bit channel can show; expected a whole number from 1 to 65536",
        ),
        (
            "--spp <N>",
            "0",
            "0 is less than 1; expected a whole number from 1 to 65536",
        ),
        (
            "--max-depth <D>",
            "-1",
            "-1 is negative; expected a whole number from 0 to 1000",
        ),
        (
            "--max-depth <D>",
            "1001",
            "1001 is more than 1000, the deepest recursion a worker's stack is sized for; \
             expected a whole number from 0 to 1000",
        ),
        (
            "--fov <DEG>",
            "0",
            "0 degrees is out of range; expected degrees between 0 and 180 (both excluded)",
        ),
        (
            "--fov <DEG>",
            "nan",
            "nan is not a finite number; expected degrees between 0 and 180 (both excluded)",
        ),
        (
            "--eye <X,Y,Z>",
            "1,2",
            "2 numbers given; expected three finite numbers separated by commas, like 1,2.5,-3",
        ),
        (
            "--up <X,Y,Z>",
            "0,inf,0",
            "inf is not a finite number; expected three finite numbers separated by commas",
        ),
    ] {
        let flag = option.split(' ').next().unwrap();
        refused(&[flag, value], 2, &invalid(option, value, cause));
    }
    refused(
        &["--width", "65535", "--height", "65535"],
        1,
        "error: --width 65535 --height 65535: the image 65535x65535 is too large: \
         at most 268435456 pixels are allowed",
    );
    refused(
        &["--eye", "1,1,1", "--look-at", "1,1,1"],
        1,
        "error: the camera asked for is invalid: the camera's eye and look_at are the same point",
    );
    refused(
        &["--up", "0,0,0"],
        1,
        "error: the camera asked for is invalid: the camera's up vector is zero",
    );
}

#[test]
fn bench_arguments_are_refused_before_a_big_scene_is_read_with_their_true_cause() {
    let dir = tempfile::tempdir().unwrap();
    write_big_obj(&dir.path().join("big.obj"), 400);
    let refused = |extra: &[&str], code, says: &str| {
        let args = [&["bench", "big.obj"][..], extra].concat();
        assert_refused_early(&args, dir.path(), code, says);
    };
    refused(
        &["--runs", "0"],
        2,
        "error: invalid value '0' for '--runs <N>': 0 is less than 1; \
         expected a whole number from 1 to 1000",
    );
    refused(
        &["--width", "-1"],
        2,
        "error: invalid value '-1' for '--width <W>': -1 is negative; \
         expected a whole number from 1 to 65535",
    );
    // 378 GB of rays: the old binary aborted allocating them, after loading.
    refused(
        &[
            "--width",
            "65535",
            "--height",
            "65535",
            "--max-memory",
            "1G",
        ],
        1,
        "error: benchmarking a 65535x65535 image (3 sets of up to 4294836225 rays) needs \
         1.6 TiB; the memory budget is 1.0 GiB (as given): use a smaller --width and --height, \
         or raise the budget with --max-memory",
    );
}

#[test]
fn scene_files_bound_their_sizes_and_counts_with_the_true_cause() {
    let dir = tempfile::tempdir().unwrap();
    let camera = "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\n";
    std::fs::write(
        dir.path().join("samples.toml"),
        format!("{camera}[render]\nwidth = 1\nheight = 1\nsamples = 4294967295\n"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("pixels.toml"),
        format!("{camera}[render]\nwidth = 65535\nheight = 65535\n"),
    )
    .unwrap();
    let view = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\n";
    std::fs::write(
        dir.path().join("polygon.nff"),
        format!("{view}resolution 1 1\np 18446744073709551615\n"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("resolution.nff"),
        format!("{view}resolution -1 99999999999999999999\n"),
    )
    .unwrap();
    for (scene, says) in [
        (
            "samples.toml",
            "samples.toml:7:11: error: `samples` must be at most 65536, got 4294967295",
        ),
        (
            "pixels.toml",
            "pixels.toml:6:10: error: the image 65535x65535 is too large: \
             at most 268435456 pixels are allowed",
        ),
        (
            "polygon.nff",
            "polygon.nff:8:3: error: the polygon's vertex count must be at most 4294967295, \
             got 18446744073709551615",
        ),
        (
            "resolution.nff",
            "resolution.nff:7:12: error: the view's resolution (width) must be at least 1, \
             got -1",
        ),
    ] {
        assert_refused_early(&["render", scene, "-o", "out.png"], dir.path(), 1, says);
    }
}

/// Issue 50, item 16: an argument of 100,000 characters is quoted at
/// about a line's width in the refusal, by clap and by our own parsers.
#[test]
fn a_huge_argument_is_quoted_at_a_lines_width() {
    let dir = tempfile::tempdir().unwrap();
    let huge_number = "7".repeat(100_000);
    let huge_words = "a ".repeat(50_000);
    for args in [
        vec!["render", "--width", &huge_number],
        vec!["explain", "--pixel", &huge_words],
        vec!["render", "--max-memory", &huge_words],
        vec!["render", "--aov", &huge_number],
        vec!["render", &huge_number],
    ] {
        let p = probe(&args, dir.path());
        assert!(matches!(p.code(), Some(1 | 2)), "{}", p.stderr);
        assert!(p.stderr.starts_with("error: "), "{}", p.stderr);
        assert!(
            p.stderr.len() < 1_500,
            "{} bytes: {}",
            p.stderr.len(),
            p.stderr
        );
        assert!(p.stderr.contains("…"), "{}", p.stderr);
    }
}
