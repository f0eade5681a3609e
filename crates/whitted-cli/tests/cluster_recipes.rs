//! The Kubernetes recipe of docs/cluster.md (deploy/kubernetes/): its
//! YAML passes the field check of `scripts/check-kubernetes-recipe.py`,
//! and the shell commands its pods run, run here as pod 0 to N-1 and the
//! merge pod would (the shared volume a folder), give the direct render
//! bit for bit. Without python3 and PyYAML the test says SKIPPED and why.

use std::path::Path;
use std::process::Command;

fn repository() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// Runs `command` with `sh -c`, `whitted` on the PATH being this build.
fn shell(command: &str, bin: &Path, index: Option<u32>) {
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut sh = Command::new("sh");
    sh.args(["-c", command]).env("PATH", path);
    if let Some(index) = index {
        sh.env("JOB_COMPLETION_INDEX", index.to_string());
    }
    let out = sh.output().unwrap();
    assert!(
        out.status.success(),
        "{command}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_kubernetes_recipe_passes_its_field_check_and_its_commands_merge_bit_for_bit() {
    let has_yaml = Command::new("python3")
        .args(["-c", "import yaml"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_yaml {
        let why = "SKIPPED: python3 with PyYAML is missing, so deploy/kubernetes/ was not checked; \
             install python3-yaml (Debian) or PyYAML (pip)";
        assert!(
            std::env::var_os("WHITTED_REQUIRE_TOOLS").is_none(),
            "{why} (WHITTED_REQUIRE_TOOLS is set, as .ci/run sets it: the tool must be there)"
        );
        eprintln!("{why}");
        return;
    }
    let check = Command::new("python3")
        .arg(repository().join("scripts/check-kubernetes-recipe.py"))
        .arg(repository().join("deploy/kubernetes"))
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "the Kubernetes recipe fails its check:\n{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let recipe: serde_json::Value = serde_json::from_slice(&check.stdout).unwrap();
    let tiles = recipe["tiles"].as_u64().unwrap() as u32;
    let mount = recipe["mount"].as_str().unwrap();

    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("volume");
    let bin = dir.path().join("bin");
    std::fs::create_dir_all(&volume).unwrap();
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_whitted"), bin.join("whitted")).unwrap();
    let scene = repository().join("scenes/whitted.toml");
    std::fs::copy(&scene, volume.join("scene.toml")).unwrap();
    let on_volume = |command: &str| command.replace(mount, volume.to_str().unwrap());
    let tile_command = on_volume(recipe["tile_command"].as_str().unwrap());
    // The pods in another order than their indices, as they may finish.
    for index in (0..tiles).rev() {
        shell(&tile_command, &bin, Some(index));
    }
    shell(
        &on_volume(recipe["merge_command"].as_str().unwrap()),
        &bin,
        None,
    );
    let direct = dir.path().join("direct.png");
    shell(
        &format!(
            "whitted render {} -o {} --quiet",
            volume.join("scene.toml").display(),
            direct.display()
        ),
        &bin,
        None,
    );
    assert!(
        std::fs::read(volume.join("frame.png")).unwrap() == std::fs::read(&direct).unwrap(),
        "the merged frame differs from the direct render"
    );
}
