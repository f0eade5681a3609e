#!/usr/bin/env python3
"""Checks the Kubernetes recipe of docs/cluster.md (deploy/kubernetes/)
field by field, as a schema check would (kubeconform cannot be installed
here), plus what makes the recipe work: an Indexed Job whose pod I renders
tile I/N with N its completions, a merge Job of exactly tiles 0..N-1, both
on the one ReadWriteMany claim. Prints the commands a pod runs as JSON,
for the test that runs them (crates/whitted-cli/tests/cluster_recipes.rs).

    python3 scripts/check-kubernetes-recipe.py deploy/kubernetes
"""

import json
import re
import sys
from pathlib import Path

import yaml

# The fields the recipe may use, as in the Kubernetes API (batch/v1 Job,
# core/v1 PersistentVolumeClaim and PodSpec): a field outside these is a
# typo or one the schema does not have.
ALLOWED = {
    "object": {"apiVersion", "kind", "metadata", "spec"},
    "metadata": {"name", "namespace", "labels", "annotations"},
    "pvc.spec": {"accessModes", "resources", "storageClassName", "volumeMode"},
    "job.spec": {
        "completionMode", "completions", "parallelism", "backoffLimit",
        "backoffLimitPerIndex", "maxFailedIndexes", "activeDeadlineSeconds",
        "ttlSecondsAfterFinished", "template", "podFailurePolicy",
    },
    "template": {"metadata", "spec"},
    "pod.spec": {"restartPolicy", "containers", "volumes", "nodeSelector",
                 "tolerations", "affinity", "securityContext"},
    "container": {"name", "image", "command", "args", "env", "resources",
                  "volumeMounts", "workingDir", "imagePullPolicy"},
    "resources": {"requests", "limits"},
    "volumeMount": {"name", "mountPath", "readOnly", "subPath"},
    "volume": {"name", "persistentVolumeClaim"},
    "claimRef": {"claimName", "readOnly"},
}
ACCESS_MODES = {"ReadWriteOnce", "ReadOnlyMany", "ReadWriteMany", "ReadWriteOncePod"}
NAME = re.compile(r"^[a-z0-9]([-a-z0-9]*[a-z0-9])?$")

errors = []


def fail(where, why):
    errors.append(f"{where}: {why}")


def fields(where, value, kind):
    if not isinstance(value, dict):
        fail(where, f"expected a mapping, found {type(value).__name__}")
        return {}
    for key in value:
        if key not in ALLOWED[kind]:
            fail(where, f"unknown field `{key}`; expected one of {sorted(ALLOWED[kind])}")
    return value


def positive_int(where, value):
    if not isinstance(value, int) or isinstance(value, bool) or value < 1:
        fail(where, f"expected a whole number of at least 1, found {value!r}")
        return None
    return value


def check_object(path, doc, api, kind):
    doc = fields(path, doc, "object")
    if doc.get("apiVersion") != api or doc.get("kind") != kind:
        fail(path, f"expected apiVersion {api} and kind {kind}, found "
                   f"{doc.get('apiVersion')} {doc.get('kind')}")
    meta = fields(f"{path}: metadata", doc.get("metadata"), "metadata")
    name = meta.get("name")
    if not isinstance(name, str) or not NAME.match(name) or len(name) > 63:
        fail(f"{path}: metadata.name", f"{name!r} is not a DNS label")
    return doc.get("spec", {}), name


def check_claim(path, doc):
    spec, name = check_object(path, doc, "v1", "PersistentVolumeClaim")
    spec = fields(f"{path}: spec", spec, "pvc.spec")
    modes = spec.get("accessModes", [])
    if not set(modes) <= ACCESS_MODES:
        fail(f"{path}: spec.accessModes", f"{modes} names an unknown mode")
    if "ReadWriteMany" not in modes:
        fail(f"{path}: spec.accessModes", "the pods of several nodes write the parts: "
                                          "ReadWriteMany is needed")
    storage = spec.get("resources", {}).get("requests", {}).get("storage")
    if not isinstance(storage, str) or not re.match(r"^\d+(Ki|Mi|Gi|Ti)?$", storage):
        fail(f"{path}: spec.resources.requests.storage", f"{storage!r} is not a quantity")
    return name


def check_job(path, doc):
    """The job's spec and its one container's shell command."""
    spec, name = check_object(path, doc, "batch/v1", "Job")
    spec = fields(f"{path}: spec", spec, "job.spec")
    template = fields(f"{path}: spec.template", spec.get("template"), "template")
    pod = fields(f"{path}: spec.template.spec", template.get("spec"), "pod.spec")
    if pod.get("restartPolicy") not in ("Never", "OnFailure"):
        fail(f"{path}: restartPolicy", "a Job's pods need Never or OnFailure")
    containers = pod.get("containers") or []
    if len(containers) != 1:
        fail(f"{path}: containers", "expected one container")
        return spec, pod, {}, ""
    container = fields(f"{path}: containers[0]", containers[0], "container")
    for key in ("name", "image"):
        if not isinstance(container.get(key), str):
            fail(f"{path}: containers[0].{key}", "missing")
    fields(f"{path}: resources", container.get("resources", {}), "resources")
    volumes = {}
    for volume in pod.get("volumes", []):
        volume = fields(f"{path}: volumes", volume, "volume")
        claim = fields(f"{path}: volumes.persistentVolumeClaim",
                       volume.get("persistentVolumeClaim"), "claimRef")
        volumes[volume.get("name")] = claim.get("claimName")
    mounts = {}
    for mount in container.get("volumeMounts", []):
        mount = fields(f"{path}: volumeMounts", mount, "volumeMount")
        if mount.get("name") not in volumes:
            fail(f"{path}: volumeMounts", f"{mount.get('name')!r} is no volume of the pod")
        mounts[mount.get("mountPath")] = volumes.get(mount.get("name"))
    if container.get("command") != ["sh", "-c"] or len(container.get("args", [])) != 1:
        fail(f"{path}: containers[0]", "expected command [sh, -c] and one argument")
        return spec, pod, mounts, ""
    return spec, pod, mounts, container["args"][0]


def main(folder):
    folder = Path(folder)
    claim_path = folder / "volume.yaml"
    tiles_path = folder / "render-tiles-job.yaml"
    merge_path = folder / "merge-job.yaml"
    claim = check_claim(claim_path, yaml.safe_load(claim_path.read_text()))
    tiles, _, tile_mounts, tile_command = check_job(tiles_path, yaml.safe_load(tiles_path.read_text()))
    _, _, merge_mounts, merge_command = check_job(merge_path, yaml.safe_load(merge_path.read_text()))

    if tiles.get("completionMode") != "Indexed":
        fail(f"{tiles_path}: spec.completionMode", "expected Indexed (pod I renders tile I)")
    count = positive_int(f"{tiles_path}: spec.completions", tiles.get("completions"))
    parallel = positive_int(f"{tiles_path}: spec.parallelism", tiles.get("parallelism"))
    if count and parallel and parallel > count:
        fail(f"{tiles_path}: spec.parallelism", "more pods than tiles")
    tile = re.search(r'--tile "\$JOB_COMPLETION_INDEX/(\d+)"', tile_command)
    if not tile:
        fail(f"{tiles_path}: args", 'expected --tile "$JOB_COMPLETION_INDEX/N"')
    elif count and int(tile.group(1)) != count:
        fail(f"{tiles_path}: args", f"--tile .../{tile.group(1)} but {count} completions")
    merged = re.search(r"seq -f (\S+) 0 (\d+)", merge_command)
    if not merged:
        fail(f"{merge_path}: args", "expected the parts as $(seq -f PATTERN 0 N-1)")
    elif count and int(merged.group(2)) != count - 1:
        fail(f"{merge_path}: args", f"merges tiles 0 to {merged.group(2)}, "
                                    f"but there are {count}")
    for path, mounts in ((tiles_path, tile_mounts), (merge_path, merge_mounts)):
        if list(mounts.values()) != [claim]:
            fail(path, f"expected the one claim {claim!r} mounted, found {mounts}")
    if tile_mounts.keys() != merge_mounts.keys():
        fail(merge_path, "mounts the claim elsewhere than the tiles do")
    if errors:
        print("\n".join(errors), file=sys.stderr)
        return 1
    print(json.dumps({
        "tiles": count,
        "mount": next(iter(tile_mounts)),
        "tile_command": tile_command,
        "merge_command": merge_command,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "deploy/kubernetes"))
