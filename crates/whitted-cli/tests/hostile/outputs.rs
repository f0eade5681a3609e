//! Outputs and printing (issue 23, items 1, 9, 10, 11, 12 and the output
//! messages of 19): a closed or full stream ends the reports, not the work;
//! only files the user could write are replaced, keeping their mode, owner
//! and links; two outputs to one file are found by canonical path and
//! identity; a signal leaves no partial file; bad destinations are refused
//! with their true cause before the scene is read.

use std::fs;
use std::io::{BufRead, BufReader};
use std::os::unix::fs::{MetadataExt, PermissionsExt, symlink};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::{Probe, probe, run, whitted};

/// The user id of `nobody`, to run as an unprivileged user when the tests
/// run as root.
const NOBODY: u32 = 65534;

/// A scene with nothing in it: each pixel is one missed ray, so a big
/// image is cheap to render and its time goes to encoding.
const EMPTY_SCENE: &str = "[render]\nbackground = [0.2, 0.3, 0.4]\n\n\
                           [camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\nfov = 45\n";

const TINY: [&str; 4] = ["--width", "8", "--height", "6"];

fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

/// `whitted args` in `dir`, as an unprivileged user: `nobody` when the
/// tests run as root (the folder is opened to everyone for it), else the
/// user running the tests, who is not privileged.
fn unprivileged(args: &[&str], dir: &Path) -> Command {
    let mut command = whitted(args, dir);
    if is_root() {
        fs::set_permissions(dir, fs::Permissions::from_mode(0o777)).unwrap();
        command.uid(NOBODY).gid(NOBODY);
    }
    command
}

fn tiny_render(extra: &[&str], dir: &Path) -> Probe {
    let mut args = vec!["render"];
    args.extend(TINY);
    args.extend(extra);
    probe(&args, dir)
}

fn partial_files(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".partial"))
        .collect()
}

#[test]
fn a_closed_or_full_stderr_ends_the_reports_not_the_render() {
    let dir = tempfile::tempdir().unwrap();
    // A pipe whose reader is gone before the command starts: every report
    // fails with EPIPE (before, the first one panicked: exit 101, no image).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let status = whitted(&["render", "-o", "closed.png"], dir.path())
        .stdout(Stdio::null())
        .stderr(writer)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    assert!(dir.path().join("closed.png").is_file());

    let full = fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let status = whitted(&["render", "-o", "full.png", "--width", "32"], dir.path())
        .stdout(Stdio::null())
        .stderr(full)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    assert!(dir.path().join("full.png").is_file());
}

#[test]
fn bench_results_that_cannot_be_written_are_an_error_said_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let bench = [
        "bench", "-q", "--accel", "bvh", "--width", "8", "--height", "8", "--runs", "1",
    ];
    let scene = dir.path().join("empty.toml");
    fs::write(&scene, EMPTY_SCENE).unwrap();
    let with_stdout = |stdout: Stdio| {
        let mut args = bench.to_vec();
        args.push("empty.toml");
        let mut command = whitted(&args, dir.path());
        command.stdout(stdout).stderr(Stdio::piped());
        let output = command.output().unwrap();
        (
            output.status.code(),
            String::from_utf8_lossy(&output.stderr).into_owned(),
        )
    };
    let full = fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    assert_eq!(
        with_stdout(full.into()),
        (
            Some(1),
            "error: the results could not be written to standard output: No space left on \
             device (os error 28)\n"
                .to_string()
        )
    );
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    assert_eq!(
        with_stdout(writer.into()),
        (
            Some(1),
            "error: the results could not be written to standard output: Broken pipe (os \
             error 32)\n"
                .to_string()
        )
    );
}

#[test]
fn a_file_the_user_may_not_write_is_not_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let ro = dir.path().join("ro.png");
    fs::write(&ro, b"not yours").unwrap();
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o444)).unwrap();
    // As root the file belongs to root and the command runs as nobody in a
    // folder open to all: renaming over the file would succeed, which is
    // the defect. As another user, the file is that user's, read-only.
    let mut args = vec!["render", "-o", "ro.png"];
    args.extend(TINY);
    let p = run(unprivileged(&args, dir.path()));
    assert_eq!(p.code(), Some(1), "{}", p.stderr);
    assert_eq!(
        p.stderr,
        "error: ro.png: you may not write this file (permission denied), so whitted does not \
         replace it\n"
    );
    assert_eq!(fs::read(&ro).unwrap(), b"not yours");
    assert!(partial_files(dir.path()).is_empty());
}

#[test]
fn an_unwritable_folder_is_refused_before_the_scene_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let locked = dir.path().join("locked");
    fs::create_dir(&locked).unwrap();
    fs::set_permissions(&locked, fs::Permissions::from_mode(0o555)).unwrap();
    // The scene does not exist: the folder must be found first.
    let args = ["render", "missing.toml", "-o", "locked/x.png"];
    let start = Instant::now();
    let p = run(unprivileged(&args, dir.path()));
    assert_eq!(p.code(), Some(1), "{}", p.stderr);
    assert_eq!(
        p.stderr,
        "error: locked/x.png: cannot create a file in the folder locked: permission denied\n"
    );
    assert!(start.elapsed() < Duration::from_secs(5));
}

#[test]
fn a_replaced_file_keeps_its_mode_owner_and_symbolic_link() {
    let dir = tempfile::tempdir().unwrap();
    let private = dir.path().join("private.png");
    fs::write(&private, b"old").unwrap();
    fs::set_permissions(&private, fs::Permissions::from_mode(0o600)).unwrap();
    if is_root() {
        std::os::unix::fs::chown(&private, Some(NOBODY), Some(NOBODY)).unwrap();
    }
    let p = tiny_render(&["-o", "private.png"], dir.path());
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    let m = fs::metadata(&private).unwrap();
    assert_eq!(m.mode() & 0o777, 0o600, "the mode is kept");
    assert!(fs::read(&private).unwrap().starts_with(b"\x89PNG"));
    if is_root() {
        assert_eq!((m.uid(), m.gid()), (NOBODY, NOBODY), "root keeps the owner");
    }

    // A link is written through: the link stays, its target gets the image.
    fs::create_dir(dir.path().join("images")).unwrap();
    symlink("images/real.png", dir.path().join("link.png")).unwrap();
    let p = tiny_render(&["-o", "link.png"], dir.path());
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    let link = fs::symlink_metadata(dir.path().join("link.png")).unwrap();
    assert!(link.file_type().is_symlink());
    assert!(
        fs::read(dir.path().join("images/real.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    assert!(partial_files(dir.path()).is_empty());
    assert!(partial_files(&dir.path().join("images")).is_empty());
}

#[test]
fn replacing_a_file_with_other_names_says_they_keep_the_old_image() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("a.png"), b"old").unwrap();
    fs::hard_link(dir.path().join("a.png"), dir.path().join("b.png")).unwrap();
    let p = tiny_render(&["-o", "a.png"], dir.path());
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    assert!(
        p.stderr.starts_with(
            "warning: a.png: the file has 2 names (hard links); the new image replaces this \
             name only, the other 1 keep the old file\n"
        ),
        "{}",
        p.stderr
    );
    assert_eq!(fs::read(dir.path().join("b.png")).unwrap(), b"old");
    // Like every warning, silent under --quiet.
    fs::remove_file(dir.path().join("a.png")).unwrap();
    fs::hard_link(dir.path().join("b.png"), dir.path().join("a.png")).unwrap();
    let quiet = tiny_render(&["-o", "a.png", "-q"], dir.path());
    assert_eq!((quiet.code(), quiet.stderr.as_str()), (Some(0), ""));
}

#[test]
fn two_outputs_to_one_file_are_refused_however_they_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let absolute = dir.path().join("a.pfm").display().to_string();
    fs::write(dir.path().join("other.pfm"), b"old").unwrap();
    fs::hard_link(dir.path().join("other.pfm"), dir.path().join("same.pfm")).unwrap();
    symlink("a.pfm", dir.path().join("link.pfm")).unwrap();
    for (output, aov) in [
        ("a.pfm", "./a.pfm"),
        ("a.pfm", absolute.as_str()),
        ("a.pfm", "link.pfm"),
        ("other.pfm", "same.pfm"),
    ] {
        let spec = format!("depth={aov}");
        let p = tiny_render(&["-o", output, "--aov", &spec], dir.path());
        assert_eq!(p.code(), Some(1), "{aov}: {}", p.stderr);
        assert_eq!(
            p.stderr,
            format!(
                "error: --aov {spec}: that file is already an output of this render (-o {output})\n"
            )
        );
    }
    assert!(!dir.path().join("a.pfm").exists());
    assert_eq!(fs::read(dir.path().join("other.pfm")).unwrap(), b"old");
}

#[test]
fn destinations_that_are_no_image_file_say_their_true_cause() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("afile"), b"x").unwrap();
    mkfifo(&dir.path().join("pipe.png"));
    for (output, says) in [
        (
            ".png",
            "error: .png: `.png` is a hidden file's name with no extension (a leading dot does \
             not start an extension); give the file a name, such as image.png\n",
        ),
        (
            "afile/x.png",
            "error: afile/x.png: afile is a file, not a folder\n",
        ),
        (
            "no/such/x.png",
            "error: no/such/x.png: the folder no/such does not exist\n",
        ),
        (
            "pipe.png",
            "error: pipe.png: this is a named pipe, not a regular file; whitted writes images \
             to regular files only\n",
        ),
    ] {
        let p = tiny_render(&["-o", output], dir.path());
        assert_eq!((p.code(), p.stderr.as_str()), (Some(1), says), "{output}");
    }
    let pipe = fs::symlink_metadata(dir.path().join("pipe.png")).unwrap();
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(&pipe.file_type()));
}

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: c is a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
}

/// Starts a render of the empty scene at `size`² with two float AOVs
/// beside the image, its standard error piped.
fn start_big_render(dir: &Path, size: &str) -> std::process::Child {
    fs::write(dir.join("empty.toml"), EMPTY_SCENE).unwrap();
    whitted(
        &[
            "render",
            "empty.toml",
            "--width",
            size,
            "--height",
            size,
            "-o",
            "big.exr",
            "--aov",
            "depth=depth.exr",
            "--aov",
            "normal=normal.exr",
        ],
        dir,
    )
    .stdin(Stdio::null())
    .stdout(Stdio::null())
    .stderr(Stdio::piped())
    .spawn()
    .unwrap()
}

fn send(child: &std::process::Child, signal: libc::c_int) {
    // SAFETY: the pid is our own child, not yet reaped.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
}

/// Sends `signal` to a big render once it is encoding an image (a
/// partial file with bytes in it; the empty one made when the folder is
/// checked does not count) and returns how it ended.
fn signal_while_encoding(signal: libc::c_int) -> std::process::ExitStatus {
    let dir = tempfile::tempdir().unwrap();
    let mut child = start_big_render(dir.path(), "1500");
    let deadline = Instant::now() + Duration::from_secs(60);
    let encoding = loop {
        let found = fs::read_dir(dir.path()).unwrap().any(|e| {
            let e = e.unwrap();
            e.file_name().to_string_lossy().ends_with(".partial")
                && e.metadata().is_ok_and(|m| m.len() > 0)
        });
        if found || Instant::now() > deadline {
            break found;
        }
        if child.try_wait().unwrap().is_some() {
            break false;
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    assert!(encoding, "the render never wrote a partial file");
    send(&child, signal);
    let status = child.wait().unwrap();
    assert_eq!(partial_files(dir.path()), Vec::<String>::new(), "{signal}");
    assert!(!dir.path().join("big.exr").exists());
    status
}

#[test]
fn sigint_while_encoding_removes_the_partial_files_and_exits_130() {
    let status = signal_while_encoding(libc::SIGINT);
    assert_eq!(status.code(), Some(130), "{status:?}");
}

/// Issue 50, item 12: every signal that ends a process and can be caught
/// leaves no partial file, and the exit code names it.
#[test]
fn every_catchable_ending_signal_while_encoding_removes_the_partial_files() {
    for signal in [libc::SIGQUIT, libc::SIGUSR1, libc::SIGXCPU, libc::SIGALRM] {
        let status = signal_while_encoding(signal);
        assert_eq!(status.code(), Some(128 + signal), "{signal}: {status:?}");
    }
}

/// Issue 50, item 12: an output past `ulimit -f` is an error said on
/// standard error, not a silent death by SIGXFSZ, and leaves no partial
/// file, for an image and for a part.
#[test]
fn a_file_size_limit_is_an_error_with_its_cause_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("empty.toml"), EMPTY_SCENE).unwrap();
    for output in ["x.exr", "x.wpart"] {
        let mut command = whitted(
            &[
                "render",
                "empty.toml",
                "--width",
                "400",
                "--height",
                "400",
                "-o",
                output,
            ],
            dir.path(),
        );
        // SAFETY: setrlimit is async-signal-safe, as pre_exec requires.
        unsafe {
            command.pre_exec(|| {
                let limit = libc::rlimit {
                    rlim_cur: 200 * 1024,
                    rlim_max: 200 * 1024,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let p = run(command);
        assert_eq!(p.code(), Some(1), "{output}: {:?} {}", p.status, p.stderr);
        assert!(
            p.stderr.contains(output) && p.stderr.contains("File too large (os error 27)"),
            "{output}: {}",
            p.stderr
        );
        assert!(!dir.path().join(output).exists());
        assert_eq!(partial_files(dir.path()), Vec::<String>::new(), "{output}");
    }
}

#[test]
fn sigterm_while_rendering_exits_143_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = start_big_render(dir.path(), "1500");
    // The scene has been read when it says so; the render follows.
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    assert!(line.contains("empty.toml: read in"), "{line}");
    send(&child, libc::SIGTERM);
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(143), "{status:?}");
    assert_eq!(partial_files(dir.path()), Vec::<String>::new());
    assert!(!dir.path().join("big.exr").exists());
}

#[test]
fn a_signal_ignored_at_the_start_stays_ignored() {
    // As under `nohup`: a hangup must not end the render.
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("empty.toml"), EMPTY_SCENE).unwrap();
    let mut command = whitted(
        &["render", "empty.toml", "--width", "600", "--height", "600"],
        dir.path(),
    );
    // SAFETY: signal() is async-signal-safe, as pre_exec requires.
    unsafe {
        command.pre_exec(|| {
            libc::signal(libc::SIGHUP, libc::SIG_IGN);
            Ok(())
        });
    }
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    assert!(line.contains("empty.toml: read in"), "{line}");
    send(&child, libc::SIGHUP);
    assert_eq!(child.wait().unwrap().code(), Some(0));
    assert!(dir.path().join("whitted.png").is_file());
}

#[test]
fn another_users_file_in_a_sticky_folder_is_refused_before_the_render() {
    // Writable by all, but in a sticky folder only its owner may rename
    // over it: the rename would fail after the render.
    let dir = tempfile::tempdir().unwrap();
    let sticky = dir.path().join("sticky");
    fs::create_dir(&sticky).unwrap();
    fs::set_permissions(&sticky, fs::Permissions::from_mode(0o1777)).unwrap();
    let theirs = sticky.join("theirs.png");
    fs::write(&theirs, b"theirs").unwrap();
    fs::set_permissions(&theirs, fs::Permissions::from_mode(0o666)).unwrap();
    if !is_root() {
        // The tests' user owns both: nothing to refuse, and no other user
        // to be. Said, not passed silently.
        eprintln!("skipped: needs root to run as another user than the file's owner");
        return;
    }
    let args = ["render", "missing.toml", "-o", "sticky/theirs.png"];
    let p = run(unprivileged(&args, dir.path()));
    assert_eq!(p.code(), Some(1), "{}", p.stderr);
    assert_eq!(
        p.stderr,
        "error: sticky/theirs.png: the file belongs to user 0 in the folder sticky, where only \
         a file's owner may replace it (a sticky folder, like /tmp)\n"
    );
    assert_eq!(fs::read(&theirs).unwrap(), b"theirs");
}

/// A sphere whose colour is the image `tex.png`, and a floor of the model
/// `floor.obj` (with its material library `floor.mtl`).
const TEXTURED_SCENE: &str = "[render]\nwidth = 8\nheight = 6\n\
    [camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\nfov = 45\n\
    [materials.painted]\ndiffuse = { image = \"tex.png\" }\n\
    [[lights]]\ntype = \"point\"\nposition = [2, 3, -4]\n\
    [[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"painted\"\n\
    [definitions.floor]\nmesh = \"floor.obj\"\n\
    [[objects]]\ninstance = \"floor\"\n";

#[test]
fn no_output_is_written_over_a_file_the_run_reads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("s.toml"), TEXTURED_SCENE).unwrap();
    fs::write(
        d.join("floor.obj"),
        "mtllib floor.mtl\nv -2 -1 -2\nv 2 -1 -2\nv 0 -1 2\nusemtl grey\nf 1 2 3\n",
    )
    .unwrap();
    fs::write(d.join("floor.mtl"), "newmtl grey\nKd 0.5 0.5 0.5\n").unwrap();
    let p = tiny_render(&["-o", "tex.png"], d);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    symlink("s.toml", d.join("scene-link.png")).unwrap();
    symlink("floor.obj", d.join("model-link.pfm")).unwrap();
    fs::hard_link(d.join("floor.mtl"), d.join("library.exr")).unwrap();
    let kept = |name: &str| fs::read(d.join(name)).unwrap();
    let before: Vec<Vec<u8>> = ["s.toml", "tex.png", "floor.obj", "floor.mtl"]
        .iter()
        .map(|n| kept(n))
        .collect();
    let refused = |args: &[&str], option: &str, input: &str| {
        let p = probe(args, d);
        assert_eq!(p.code(), Some(1), "{args:?}: {}", p.stderr);
        // Files found from the scene are named by the path they were read
        // by (joined to the scene's folder).
        let message = format!("error: {option}: that file is an input of this run (");
        let input =
            format!("{input}); writing it would destroy it, so give the output another name\n");
        assert!(
            p.stderr.contains(&message) && p.stderr.ends_with(&input),
            "{args:?}: {}",
            p.stderr
        );
    };
    // The texture, the scene through a link, the model through a link, the
    // material library through a second name; an AOV too.
    refused(
        &["render", "s.toml", "-o", "tex.png"],
        "-o tex.png",
        "tex.png",
    );
    refused(
        &["render", "s.toml", "-o", "scene-link.png"],
        "-o scene-link.png",
        "s.toml",
    );
    refused(
        &[
            "render",
            "s.toml",
            "-o",
            "a.png",
            "--aov",
            "depth=model-link.pfm",
        ],
        "--aov depth=model-link.pfm",
        "floor.obj",
    );
    refused(
        &["render", "s.toml", "-o", "library.exr"],
        "-o library.exr",
        "floor.mtl",
    );
    // A drawing over the scene, through its own name.
    symlink("s.toml", d.join("drawing.svg")).unwrap();
    refused(
        &[
            "explain",
            "s.toml",
            "--pixel",
            "1,1",
            "--svg",
            "drawing.svg",
        ],
        "--svg drawing.svg",
        "s.toml",
    );
    // A drawing under an image's name is refused before any work.
    let p = probe(
        &["explain", "s.toml", "--pixel", "1,1", "--svg", "x.png"],
        d,
    );
    assert_eq!(p.code(), Some(1), "{}", p.stderr);
    assert_eq!(
        p.stderr,
        "error: x.png: this output is an .svg file; give a name ending in .svg\n"
    );
    assert!(!d.join("x.png").exists());
    // A merged image over one of its parts.
    for (i, tile) in ["0/2", "1/2"].iter().enumerate() {
        let part = format!("p{i}.wpart");
        let p = tiny_render(&["s.toml", "--tile", tile, "-o", &part], d);
        assert_eq!(p.code(), Some(0), "{}", p.stderr);
    }
    symlink("p0.wpart", d.join("merged.png")).unwrap();
    let part = kept("p0.wpart");
    refused(
        &["merge", "p0.wpart", "p1.wpart", "-o", "merged.png"],
        "-o merged.png",
        "p0.wpart",
    );
    assert_eq!(kept("p0.wpart"), part);
    let after: Vec<Vec<u8>> = ["s.toml", "tex.png", "floor.obj", "floor.mtl"]
        .iter()
        .map(|n| kept(n))
        .collect();
    assert!(before == after, "an input changed");
    assert!(partial_files(d).is_empty());
}

/// Issue 50, item 15: a part whose data is damaged (its checksum), forged
/// with values no render gives (a checksum that matches them), or saying
/// `spp 0` is refused by `merge` with its place; nothing is written.
#[test]
fn merge_refuses_damaged_and_forged_parts_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (i, tile) in ["0/2", "1/2"].iter().enumerate() {
        let part = format!("p{i}.wpart");
        let p = tiny_render(&["--tile", tile, "--aov", "depth", "-o", &part], d);
        assert_eq!(p.code(), Some(0), "{}", p.stderr);
    }
    let good = fs::read(d.join("p1.wpart")).unwrap();
    let data_at = good.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    let header = String::from_utf8(good[..data_at].to_vec()).unwrap();
    let hash = header
        .lines()
        .find_map(|l| l.strip_prefix("data-sha256 "))
        .unwrap()
        .to_string();
    // The part with `data` in place of its data and the header changed by
    // `edit`, its checksum made to match the data when `rehash`.
    let forge = |data: &[u8], edit: (&str, &str), rehash: bool| {
        let mut header = header.replace(edit.0, edit.1);
        if rehash {
            header = header.replace(&hash, &whitted::render::scene_sha256(data));
        }
        let mut bytes = header.into_bytes();
        bytes.extend_from_slice(data);
        fs::write(d.join("p1.wpart"), bytes).unwrap();
        probe(&["merge", "p0.wpart", "p1.wpart", "-o", "m.exr"], d)
    };
    let mut flipped = good[data_at..].to_vec();
    flipped[5] ^= 0x01;
    let mut nan = good[data_at..].to_vec();
    nan[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut negative_depth = good[data_at..].to_vec();
    negative_depth[12..16].copy_from_slice(&(-2.0f32).to_le_bytes());
    for (p, says) in [
        (
            forge(&flipped, ("", ""), false),
            "p1.wpart:15: the pixel data's SHA-256 is ",
        ),
        (
            forge(&nan, ("", ""), true),
            "p1.wpart:15: pixel (0, 1) holds the colour value NaN, which no render gives: the \
             part is damaged; render it again",
        ),
        (
            forge(&negative_depth, ("", ""), true),
            "p1.wpart:15: pixel (0, 1) holds the depth value -2, which no render gives",
        ),
        (
            forge(&good[data_at..], ("spp 1\n", "spp 0\n"), false),
            "p1.wpart:7: `spp 0`: a render takes at least one sample per pixel",
        ),
    ] {
        assert_eq!(p.code(), Some(1), "{}", p.stderr);
        assert!(
            p.stderr.starts_with("error: ") && p.stderr.contains(says),
            "{}",
            p.stderr
        );
        assert!(!d.join("m.exr").exists());
        assert!(partial_files(d).is_empty());
    }
    fs::write(d.join("p1.wpart"), &good).unwrap();
    let p = probe(&["merge", "p0.wpart", "p1.wpart", "-o", "m.exr"], d);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
}

/// Issue 50, item 14: results asked of a command whose standard output is
/// closed (`>&-`) are refused before any work, as a full one is after it;
/// `render`, which writes none there, runs.
#[test]
fn a_closed_stdout_is_an_error_for_the_commands_that_write_results_there() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("empty.toml"), EMPTY_SCENE).unwrap();
    let closed_stdout = |args: &[&str]| {
        let mut command = whitted(args, dir.path());
        // SAFETY: close() is async-signal-safe, as pre_exec requires.
        unsafe {
            command.pre_exec(|| {
                libc::close(libc::STDOUT_FILENO);
                Ok(())
            });
        }
        run(command)
    };
    let says = "error: standard output is closed (as with `>&-`), and this command writes its \
                results there; redirect it to a file, or to /dev/null to drop them\n";
    for args in [
        &["explain", "empty.toml", "--pixel", "1,1", "--svg", "x.svg"][..],
        &["explain", "empty.toml", "--pixel", "1,1", "--json"],
        &[
            "bench",
            "-q",
            "--accel",
            "bvh",
            "--width",
            "8",
            "--height",
            "8",
            "empty.toml",
        ],
    ] {
        let p = closed_stdout(args);
        assert_eq!(p.code(), Some(1), "{args:?}: {}", p.stderr);
        assert_eq!(p.stderr, says, "{args:?}");
    }
    assert!(!dir.path().join("x.svg").exists());
    let p = closed_stdout(&[
        "render",
        "empty.toml",
        "--width",
        "8",
        "--height",
        "6",
        "-q",
    ]);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    assert!(dir.path().join("whitted.png").is_file());
}
