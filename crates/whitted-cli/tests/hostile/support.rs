//! Running `whitted` as a hostile user would, and measuring what it did.

use std::io::Read;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};

/// What one run of `whitted` did.
#[derive(Debug)]
pub struct Probe {
    /// How the process ended.
    pub status: ExitStatus,
    /// Everything it printed on standard output.
    pub stdout: String,
    /// Everything it printed on standard error.
    pub stderr: String,
    /// Its peak resident memory in bytes (from `wait4`'s resource usage):
    /// an upper bound, as the count starts from the test process's own
    /// size when the child is spawned (a few MiB).
    pub peak_bytes: u64,
}

impl Probe {
    /// The exit code (`None` when killed by a signal).
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }
}

/// A `whitted` command with `args`, run in `dir`.
pub fn whitted(args: &[&str], dir: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_whitted"));
    command.args(args).current_dir(dir);
    command
}

/// Runs `whitted args` in `dir` and measures it.
pub fn probe(args: &[&str], dir: &Path) -> Probe {
    run(whitted(args, dir))
}

/// Runs `command` with its output captured, and reaps it with `wait4` to
/// read its own peak memory (not the sum or the maximum over every child
/// of the test process, which `getrusage(RUSAGE_CHILDREN)` would give).
pub fn run(mut command: Command) -> Probe {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the whitted binary runs");
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let out_reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        out.read_to_end(&mut s).unwrap();
        s
    });
    let err_reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        err.read_to_end(&mut s).unwrap();
        s
    });
    let (status, peak_bytes) = wait_measured(child.id());
    // `child` was reaped by wait4: dropping it must not wait again (it
    // does not: dropping a Child never waits).
    drop(child);
    Probe {
        status,
        stdout: String::from_utf8_lossy(&out_reader.join().unwrap()).into_owned(),
        stderr: String::from_utf8_lossy(&err_reader.join().unwrap()).into_owned(),
        peak_bytes,
    }
}

/// Waits for process `pid` and returns its status and peak resident bytes.
fn wait_measured(pid: u32) -> (ExitStatus, u64) {
    use std::os::unix::process::ExitStatusExt;
    let mut status = 0;
    // SAFETY: rusage is plain data that wait4 fills in.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: pid is our own child, status and usage are valid for writes.
        let r = unsafe { libc::wait4(pid as libc::pid_t, &mut status, 0, &mut usage) };
        if r == pid as libc::pid_t {
            break;
        }
        let e = std::io::Error::last_os_error();
        assert_eq!(e.kind(), std::io::ErrorKind::Interrupted, "wait4: {e}");
    }
    // Linux reports ru_maxrss in KiB.
    let peak = u64::try_from(usage.ru_maxrss).unwrap_or(0) * 1024;
    (ExitStatus::from_raw(status), peak)
}

/// Bytes in a mebibyte, for readable memory bounds.
pub const MIB: u64 = 1 << 20;

#[test]
fn a_probe_measures_exit_code_output_and_peak_memory() {
    let dir = tempfile::tempdir().unwrap();
    let p = probe(&["render", "--width", "16", "--height", "12"], dir.path());
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    assert!(p.stderr.contains("16x12"), "{}", p.stderr);
    assert!(p.stdout.is_empty(), "{}", p.stdout);
    assert!(
        p.peak_bytes > MIB && p.peak_bytes < 512 * MIB,
        "{}",
        p.peak_bytes
    );
    assert!(dir.path().join("whitted.png").is_file());
}
