#!/usr/bin/env python3
"""The bar of adaptive anti-aliasing (issue 19): on scenes/whitted.toml and
three SPD scenes, the adaptive picture against a 64-spp stratified
reference, with the camera rays and times of both.

    scripts/adaptive-aa.py BINARY [--size N] [--threshold T] [--depth D]
                           [--min-depth M] [--threads T] [--scenes DIR]
                           [--spd NAME ...] [--only NAME ...]

The defaults are the setting docs/performance-log.md reports (512x512,
threshold 0.1, depth 4, minimum depth 1) on balls, gears and teapot from
../shared/scenes/spd; `--spd` names other SPD scenes.

For each scene it renders the reference (`--spp 64`) and the adaptive
picture (`--aa adaptive --aa-threshold T --aa-depth D --aa-min-depth M`)
as PFM, encodes both
as the PNG writer would (8-bit codes through the sRGB curve for linear
scenes, scaled for NFF's display values) and reports the mean absolute
error per channel (in 1/255), the share of pixels whose channels are all
within 8/255, the camera rays of each and the adaptive share of the
reference's. The bar: MAE < 0.5/255, 99.9% of pixels within 8/255, fewer
than 30% of the reference's camera rays. Exits 1 when a scene misses it.
"""

import argparse
import os
import re
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        channels = 3 if kind == b"PF" else 1
        count = width * height * channels
        data = f.read(4 * count)
    endian = "<" if scale < 0 else ">"
    return width, height, struct.unpack(f"{endian}{count}f", data)


def srgb8(v):
    v = 0.0 if v != v else min(max(v, 0.0), 1.0)
    e = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(e * 255.0 + 0.5)


def display8(v):
    v = 0.0 if v != v else min(max(v, 0.0), 1.0)
    return int(v * 255.0 + 0.5)


def render(binary, scene, out, extra, size, threads):
    args = [binary, "render", scene, "-o", out, "--width", str(size),
            "--height", str(size)] + extra
    if threads:
        args += ["--threads", str(threads)]
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    summary = done.stderr
    seconds = float(re.search(r" in ([0-9.]+) s[; ]", summary).group(1))
    primary = int(re.search(r"(\d+) primary", summary).group(1))
    total = sum(int(n) for n in re.findall(r"(\d+) [a-z]+(?:,|;)", summary.split("rays:")[1]))
    return seconds, primary, total


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("binary")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--threshold", type=float, default=0.1)
    parser.add_argument("--depth", type=int, default=4)
    parser.add_argument("--min-depth", type=int, default=1)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--scenes", default=os.path.join(ROOT, "..", "shared", "scenes", "spd"))
    parser.add_argument("--spd", nargs="*", default=["balls", "gears", "teapot"],
                        help="SPD scenes (names without .nff) besides scenes/whitted.toml")
    parser.add_argument("--only", nargs="*", help="scene names to run")
    a = parser.parse_args()
    scenes = [os.path.join(ROOT, "scenes/whitted.toml")] + [
        os.path.join(a.scenes, n + ".nff") for n in a.spd]
    if a.only:
        scenes = [s for s in scenes if os.path.basename(s).split(".")[0] in a.only]
    print(f"{a.size}x{a.size}; adaptive threshold {a.threshold}, depth {a.depth}, "
          f"min depth {a.min_depth}; "
          "reference 64 spp stratified")
    print(f"{'scene':<14} {'ref rays':>10} {'ref s':>7} {'aa rays':>10} {'aa s':>7} "
          f"{'cam %':>6} {'MAE/255':>8} {'<=8/255':>8} {'max':>4}  bar")
    missed = False
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            encode = display8 if scene.endswith(".nff") else srgb8
            ref_out = os.path.join(tmp, "ref.pfm")
            aa_out = os.path.join(tmp, "aa.pfm")
            ref_s, ref_primary, ref_total = render(
                a.binary, scene, ref_out, ["--spp", "64"], a.size, a.threads)
            aa_s, aa_primary, aa_total = render(
                a.binary, scene, aa_out,
                ["--aa", "adaptive", "--aa-threshold", str(a.threshold),
                 "--aa-depth", str(a.depth), "--aa-min-depth", str(a.min_depth)],
                a.size, a.threads)
            _, _, ref = read_pfm(ref_out)
            _, _, aa = read_pfm(aa_out)
            codes_ref = [encode(v) for v in ref]
            codes_aa = [encode(v) for v in aa]
            diffs = [abs(p - q) for p, q in zip(codes_ref, codes_aa)]
            mae = sum(diffs) / len(diffs)
            pixels = len(diffs) // 3
            within = sum(1 for i in range(pixels) if max(diffs[3 * i:3 * i + 3]) <= 8)
            share = within / pixels
            ratio = aa_primary / ref_primary
            ok = mae < 0.5 and share >= 0.999 and ratio < 0.30
            missed |= not ok
            print(f"{os.path.basename(scene):<14} {ref_primary:>10} {ref_s:>7.2f} "
                  f"{aa_primary:>10} {aa_s:>7.2f} {100 * ratio:>5.1f}% {mae:>8.3f} "
                  f"{100 * share:>7.2f}% {max(diffs):>4}  {'met' if ok else 'MISSED'}",
                  flush=True)
            print(f"{'':<14} all rays: reference {ref_total}, adaptive {aa_total} "
                  f"({100 * aa_total / ref_total:.1f}%)", flush=True)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
