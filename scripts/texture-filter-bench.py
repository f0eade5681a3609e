#!/usr/bin/env python3
"""Texture filtering against a supersampled reference (issue 19).

For each scene: renders a 256-spp reference (stratified, unfiltered), then
1 spp without and with `--texture-filter mipmap`, and reports each 1-spp
picture's error against the reference in 8-bit display units (the sRGB
encoding of the linear PFM values, times 255, not rounded): the mean
absolute error per channel and the share of pixels whose largest channel
error is at most 8/255. Also times the two 1-spp renders (best of 3).

    scripts/texture-filter-bench.py target/release/whitted [OUT_DIR]

Needs only Python 3.
"""

import struct
import subprocess
import sys
import time
from pathlib import Path

SCENES = [
    ("grazing-checker", "scenes/grazing-checker.toml", []),
    ("shapes", "scenes/shapes.toml", ["--width", "480", "--height", "360"]),
]


def read_pfm(path):
    data = Path(path).read_bytes()
    parts = data.split(b"\n", 3)
    kind, size, scale, body = parts[0], parts[1], parts[2], parts[3]
    assert kind == b"PF", path
    width, height = map(int, size.split())
    endian = "<" if float(scale) < 0 else ">"
    values = struct.unpack(f"{endian}{width * height * 3}f", body[: width * height * 12])
    return width, height, values


def srgb(x):
    x = min(max(x, 0.0), 1.0)
    return 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055


def errors(a, b):
    (w, h, va), (_, _, vb) = a, b
    total, within = 0.0, 0
    for p in range(w * h):
        worst = 0.0
        for c in range(3):
            e = abs(srgb(va[3 * p + c]) - srgb(vb[3 * p + c])) * 255
            total += e
            worst = max(worst, e)
        within += worst <= 8
    return total / (3 * w * h), within / (w * h)


def render(whitted, scene, out, args):
    best = None
    for _ in range(3 if "--spp" not in args else 1):
        start = time.perf_counter()
        subprocess.run([whitted, "render", scene, "--quiet", "-o", out, *args], check=True)
        took = time.perf_counter() - start
        best = took if best is None else min(best, took)
    return best


def main():
    whitted = str(Path(sys.argv[1]).resolve())
    out = Path(sys.argv[2] if len(sys.argv) > 2 else "/tmp/texture-filter")
    out.mkdir(parents=True, exist_ok=True)
    print("scene            picture        MAE/255  within 8/255  time (s)")
    for name, scene, extra in SCENES:
        ref = out / f"{name}.ref.pfm"
        render(whitted, scene, str(ref), [*extra, "--spp", "256"])
        reference = read_pfm(ref)
        for label, args in [("1 spp, none", []), ("1 spp, mipmap", ["--texture-filter", "mipmap"])]:
            path = out / f"{name}.{args[-1] if args else 'none'}.pfm"
            took = render(whitted, scene, str(path), [*extra, *args])
            mae, within = errors(read_pfm(path), reference)
            print(f"{name:16} {label:14} {mae:7.3f}  {100 * within:10.3f}%  {took:8.3f}")


if __name__ == "__main__":
    main()
