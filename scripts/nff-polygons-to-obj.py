#!/usr/bin/env python3
"""Writes an NFF scene's polygons and patches (`p`, `pp`) as a Wavefront OBJ
for the Embree harness (../shared/peers/embree), turned so that the scene's
`up` is +y (the harness's camera keeps (0, 1, 0) up), and prints the
harness's flags for the scene's own view and first light.

Spheres, cones and cylinders are left out: the harness traces triangles
only. Polygons are written whole; the harness fans them into triangles, which
matches the polygon only where it is convex (the SPD meshes are triangles).

Usage (from the repository root):
    python3 scripts/nff-polygons-to-obj.py ../shared/scenes/spd/mount.nff /tmp/mount.obj
    # prints: --eye ... --target ... --fov ... --light ...
Then, with the harness built (see scripts/compare-embree.py):
    mkdir -p /tmp/anchor_rays/mount
    /tmp/embree-bench /tmp/mount.obj FLAGS --dump /tmp/anchor_rays/mount
    /tmp/embree-bench /tmp/mount.obj FLAGS --quality medium --runs 5
    target/release/whitted bench /tmp/mount.obj --rays /tmp/anchor_rays/mount --accel bvh --runs 5
"""
import math
import sys


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    source, target = sys.argv[1], sys.argv[2]
    tokens = []
    for line in open(source).read().splitlines():
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        # A light's colour, if given, is not needed.
        tokens += words[:4] if words[0] == "l" else words
    view = {}
    light = None
    polygons = []
    i = 0

    def numbers(k):
        nonlocal i
        values = [float(t) for t in tokens[i : i + k]]
        i += k
        return values

    while i < len(tokens):
        t = tokens[i]
        i += 1
        if t in ("from", "at", "up"):
            view[t] = numbers(3)
        elif t == "angle":
            view[t] = numbers(1)[0]
        elif t == "l":
            position = numbers(3)
            light = light or position
        elif t in ("p", "pp"):
            count = int(tokens[i])
            i += 1
            width = 3 if t == "p" else 6
            polygons.append([numbers(width)[:3] for _ in range(count)])
        elif t == "s":
            numbers(4)
        elif t == "c":
            numbers(8)
        elif t == "f":
            numbers(8)
        elif t == "b":
            numbers(3)
        elif t in ("hither", "resolution", "v"):
            i += {"hither": 1, "resolution": 2, "v": 0}[t]
        else:
            sys.exit(f"{source}: token {t!r} not handled")
    # An orthonormal frame (a, up, b) with up -> +y, a -> +x, b -> +z.
    up = normalize(view["up"])
    helper = [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 0.0, 1.0]
    b = normalize(cross(helper, up))
    a = cross(up, b)

    def turn(p):
        return [dot(p, a), dot(p, up), dot(p, b)]

    with open(target, "w") as out:
        n = 0
        faces = []
        for polygon in polygons:
            first = n + 1
            for p in polygon:
                out.write("v %r %r %r\n" % tuple(turn(p)))
                n += 1
            faces.append(range(first, n + 1))
        for face in faces:
            out.write("f " + " ".join(map(str, face)) + "\n")
    eye, at = turn(view["from"]), turn(view["at"])
    flags = ["--eye", *eye, "--target", *at, "--fov", view["angle"]]
    if light:
        flags += ["--light", *turn(light)]
    print(" ".join(f"{x:.9g}" if isinstance(x, float) else x for x in flags))
    print(f"{target}: {len(polygons)} polygons", file=sys.stderr)


main()
