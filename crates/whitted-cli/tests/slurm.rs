//! The Slurm recipe of docs/cluster.md on a real Slurm: the job array of
//! 4 tiles and the dependent merge job (`deploy/slurm/submit.sh`) give the
//! direct render of the built-in scene, bit for bit.
//!
//! Needs a running cluster (`scripts/slurm-single-node.sh` starts one on
//! this machine; `.ci/run` does). Without `sbatch` the test says SKIPPED
//! and why, and passes (unless `WHITTED_REQUIRE_TOOLS` is set, as `.ci/run`
//! sets it); with `sbatch` but no working cluster it fails.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// The longest the round trip may take.
const TIMEOUT: Duration = Duration::from_secs(60);

fn repository() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// What `program args` printed, or why it failed.
fn output(program: &str, args: &[&str], dir: &Path) -> Result<String, String> {
    let out = Command::new(program)
        .args(args)
        .current_dir(dir)
        .env("WHITTED", env!("CARGO_BIN_EXE_whitted"))
        .output()
        .map_err(|e| format!("{program}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{program} {args:?}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The state of job `id` (`COMPLETED`, `PENDING`, ...).
fn job_state(id: &str, dir: &Path) -> Result<String, String> {
    let shown = output("scontrol", &["show", "job", "-o", id], dir)?;
    shown
        .split_whitespace()
        .find_map(|field| field.strip_prefix("JobState="))
        .map(str::to_string)
        .ok_or_else(|| format!("no JobState in `{shown}`"))
}

/// Every Slurm log in `dir`, to explain a failure.
fn logs(dir: &Path) -> String {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|entry| {
            let path = entry.ok()?.path();
            (path.extension()? == "log").then(|| {
                format!(
                    "--- {}\n{}",
                    path.display(),
                    std::fs::read_to_string(&path).unwrap_or_default()
                )
            })
        })
        .collect()
}

#[test]
fn the_slurm_job_array_and_merge_job_give_the_direct_render_bit_for_bit() {
    if Command::new("sbatch").arg("--version").output().is_err() {
        let why = "SKIPPED: sbatch is not installed, so the Slurm round trip was not tested; \
             scripts/slurm-single-node.sh installs Slurm and starts a one-node cluster";
        assert!(
            std::env::var_os("WHITTED_REQUIRE_TOOLS").is_none(),
            "{why} (WHITTED_REQUIRE_TOOLS is set, as .ci/run sets it: the tool must be there)"
        );
        eprintln!("{why}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let start = Instant::now();
    let submit = repository().join("deploy/slurm/submit.sh");
    let merge_job = output(submit.to_str().unwrap(), &["4", "parts", "slurm.png"], dir)
        .unwrap_or_else(|e| panic!("{e}\n(is the cluster up? scripts/slurm-single-node.sh)"));
    loop {
        let state = job_state(&merge_job, dir).unwrap();
        match state.as_str() {
            "COMPLETED" => break,
            "PENDING" | "RUNNING" | "COMPLETING" | "CONFIGURING" => {}
            _ => panic!("the merge job {merge_job} ended {state}\n{}", logs(dir)),
        }
        assert!(
            start.elapsed() < TIMEOUT,
            "the merge job {merge_job} is still {state} after {TIMEOUT:?}\n{}",
            logs(dir)
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    let round_trip = start.elapsed();
    let direct = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(["render", "-o", "direct.png", "--quiet"])
        .current_dir(dir)
        .status()
        .unwrap();
    assert!(direct.success());
    let merged = std::fs::read(dir.join("slurm.png")).unwrap();
    assert!(
        merged == std::fs::read(dir.join("direct.png")).unwrap(),
        "the merged image differs from the direct render\n{}",
        logs(dir)
    );
    eprintln!("Slurm round trip of 4 tiles and the merge: {round_trip:.1?}");
}
