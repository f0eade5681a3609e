#!/usr/bin/env python3
"""Writes two scenes for `whitted bench`: 1,000 tori and 1,000 spheres of the
same sizes at the same random places (seeded), so that their Mrays/s compare
the torus's quartic with the sphere's quadratic.

    python3 scripts/torus-bench-scenes.py OUT_DIR
    whitted bench --accel bvh OUT_DIR/tori-1000.toml
    whitted bench --accel bvh OUT_DIR/spheres-1000.toml
"""

import math
import random
import sys
from pathlib import Path

COUNT = 1000
HEADER = """[camera]
eye = [0, 0, -30]
look_at = [0, 0, 0]
fov = 50

[materials.plain]
diffuse = [0.8, 0.8, 0.8]

[[lights]]
type = "point"
position = [-20, 30, -40]
"""


def placements():
    """COUNT (centre, axis, angle, major, minor) in a cube of side 20."""
    rng = random.Random(17)
    for _ in range(COUNT):
        centre = [rng.uniform(-10, 10) for _ in range(3)]
        axis = [rng.gauss(0, 1) for _ in range(3)]
        angle = rng.uniform(0, 180)
        major = rng.uniform(0.3, 0.8)
        minor = major * rng.uniform(0.15, 0.5)
        yield centre, axis, angle, major, minor


def fmt(v):
    return "[" + ", ".join(f"{x:.6f}" for x in v) + "]"


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    out.mkdir(parents=True, exist_ok=True)
    tori, spheres = [HEADER], [HEADER]
    for centre, axis, angle, major, minor in placements():
        tori.append(
            f'\n[[objects]]\nshape = "torus"\nmajor = {major:.6f}\nminor = {minor:.6f}\n'
            f'material = "plain"\ntransform = [{{ rotate = {{ axis = {fmt(axis)}, '
            f"angle = {angle:.3f} }} }}, {{ translate = {fmt(centre)} }}]\n"
        )
        spheres.append(
            f'\n[[objects]]\nshape = "sphere"\ncenter = {fmt(centre)}\n'
            f'radius = {major + minor:.6f}\nmaterial = "plain"\n'
        )
    (out / "tori-1000.toml").write_text("".join(tori))
    (out / "spheres-1000.toml").write_text("".join(spheres))


if __name__ == "__main__":
    main()
