#!/usr/bin/env python3
"""Writes two bench scenes of 1,000 shapes at the same random places (seed 17):
superellipsoids (e and n drawn from 0.2 to 3) and spheres of the same radius.

    python3 scripts/superellipsoid-bench-scenes.py /tmp/se-bench
    whitted bench /tmp/se-bench/superellipsoids.toml --accel bvh --width 512 --height 512
    whitted bench /tmp/se-bench/spheres.toml --accel bvh --width 512 --height 512
"""

import random
import sys
from pathlib import Path

HEADER = """[camera]
eye = [0, 0, -30]
look_at = [0, 0, 0]
fov = 45

[[lights]]
type = "point"
position = [-20, 30, -40]
"""


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/superellipsoid-bench")
    out.mkdir(parents=True, exist_ok=True)
    rng = random.Random(17)
    places = [
        ([rng.uniform(-10, 10) for _ in range(3)], rng.uniform(0.3, 0.8),
         rng.uniform(0.2, 3.0), rng.uniform(0.2, 3.0))
        for _ in range(1000)
    ]
    supers, spheres = [HEADER], [HEADER]
    for (x, y, z), radius, e, n in places:
        center = f"[{x:.4f}, {y:.4f}, {z:.4f}]"
        supers.append(
            f'[[objects]]\nshape = "superellipsoid"\ne = {e:.3f}\nn = {n:.3f}\n'
            f"center = {center}\nradius = {radius:.4f}\n"
        )
        spheres.append(f'[[objects]]\nshape = "sphere"\ncenter = {center}\nradius = {radius:.4f}\n')
    (out / "superellipsoids.toml").write_text("\n".join(supers))
    (out / "spheres.toml").write_text("\n".join(spheres))


if __name__ == "__main__":
    main()
