#!/usr/bin/env python3
"""Embree MEDIUM and whitted (every structure) on the same rays, back to back,
best over rounds; prints the ratio tables in Markdown.

Usage (from the repository root, after `cargo build --release`):
    ../shared/peers/embree/build.sh /tmp/embree-bench
    for m in bunny dragon; do /tmp/embree-bench ../shared/scenes/models/$m/$m.obj --dump /tmp/anchor_rays/$m; done
    /tmp/embree-bench ../shared/scenes/models/kitchen/kitchen.obj --dump /tmp/anchor_rays/kitchen KITCHEN_VIEW
    python3 scripts/compare-embree.py bunny,kitchen,dragon 2
with KITCHEN_VIEW the interior camera below (the harness's run_all.sh uses it).
Environment: EMBREE_BENCH (default /tmp/embree-bench), RAYS (default
/tmp/anchor_rays), SHARED (default ../shared), WHITTED (default
target/release/whitted).
"""
import json, os, subprocess, sys
MODELS = sys.argv[1].split(",")
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 2
W = os.environ.get("WHITTED", "target/release/whitted")
EMBREE = os.environ.get("EMBREE_BENCH", "/tmp/embree-bench")
RAYS = os.environ.get("RAYS", "/tmp/anchor_rays")
SHARED = os.environ.get("SHARED", "../shared")
KITCHEN = ["--eye", "3.0", "1.5", "1.4", "--target", "-3.9438584", "1.5", "-1.7303504", "--light", "0.84", "2.3", "0.06"]
best = {}
def keep(key, v, low=False):
    if key not in best or (v < best[key] if low else v > best[key]): best[key] = v
for r in range(ROUNDS):
    for m in MODELS:
        obj = f"{SHARED}/scenes/models/{m}/{m}.obj"
        out = subprocess.run([EMBREE, obj, "--runs", "3"] + (KITCHEN if m == "kitchen" else []), capture_output=True, text=True).stdout
        res = json.loads([l for l in out.splitlines() if l.startswith("RESULT ")][0][7:])
        md = res["medium"]
        for k in ("primary", "shadow", "diffuse"):
            keep((m, "embree", k, 1), md[k]["1T_best"]); keep((m, "embree", k, 2), md[k]["2T_best"])
        bm = [l for l in out.splitlines() if l.startswith("build_medium")][0]
        keep((m, "embree", "build"), float(bm.split("min")[1].split("ms")[0]), low=True)
        ours = json.loads(subprocess.run([W, "bench", obj, "--rays", f"{RAYS}/{m}", "--accel", "all", "--runs", "3", "--json"], capture_output=True, text=True).stdout)
        for s in ours["structures"]:
            a = s["accel"]
            keep((m, a, "build"), s["build_ms"], low=True)
            for k in s["kinds"]:
                keep((m, a, k["rays"], 1), k["mrays_per_s_1_thread"]); keep((m, a, k["rays"], 2), k["mrays_per_s_all_threads"])
                keep((m, a, k["rays"], "agree"), k["agreeing"] / k["count"]); best[(m, a, k["rays"], "nodes")] = k["nodes_per_ray"]
        print(f"round {r+1} {m} done", file=sys.stderr)
print("| model | kind | Embree 1T | BVH 1T | ratio | Embree 2T | BVH 2T | ratio |")
print("|---|---|---|---|---|---|---|---|")
for m in MODELS:
    for k in ("primary", "shadow", "diffuse"):
        e1, e2 = best[(m, "embree", k, 1)], best[(m, "embree", k, 2)]
        b1, b2 = best[(m, "bvh", k, 1)], best[(m, "bvh", k, 2)]
        print(f"| {m} | {k} | {e1:.2f} | {b1:.2f} | {b1/e1:.2f} | {e2:.2f} | {b2:.2f} | {b2/e2:.2f} |")
print()
print("| model | build Embree MEDIUM (min ms) | BVH (best ms) | ratio |")
print("|---|---|---|---|")
for m in MODELS:
    e, b = best[(m, "embree", "build")], best[(m, "bvh", "build")]
    print(f"| {m} | {e:.1f} | {b:.1f} | {b/e:.2f}x |")
print()
print("| model | kind | kd-tree / BVH time 1T | 2T | grid Mrays/s 1T | grid nodes/ray | min agreement (all structures) |")
print("|---|---|---|---|---|---|---|")
for m in MODELS:
    for k in ("primary", "shadow", "diffuse"):
        kd1 = best[(m, "bvh", k, 1)] / best[(m, "kdtree", k, 1)]; kd2 = best[(m, "bvh", k, 2)] / best[(m, "kdtree", k, 2)]
        agree = min(best[(m, a, k, "agree")] for a in ("bvh", "kdtree", "grid", "linear") if (m, a, k, "agree") in best)
        print(f"| {m} | {k} | {kd1:.2f} | {kd2:.2f} | {best[(m,'grid',k,1)]:.2f} | {best[(m,'grid',k,'nodes')]:.1f} | {100*agree:.4f}% |")
