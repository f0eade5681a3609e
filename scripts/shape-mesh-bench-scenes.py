#!/usr/bin/env python3
"""Writes pairs of bench scenes: the new shapes intersected exactly (TOML) and
the same shapes tessellated into smooth triangle meshes (NFF `pp` patches,
which whitted reads as meshes), with the same camera and light, so that
`whitted bench` measures "as fast as a mesh of the same look" side by side.

    python3 scripts/shape-mesh-bench-scenes.py OUT_DIR
    for s in spheres quadrics tori implicit-tori superellipsoids teapot-12 teapot-32; do
        whitted bench --accel bvh --width 512 --height 512 OUT_DIR/$s.toml
        whitted bench --accel bvh --width 512 --height 512 OUT_DIR/$s-mesh.nff
    done

Each family is 125 shapes (seed 17) in a cube of side 10 seen from 20 away,
each some 30 to 80 pixels across at 512x512 (the implicit tori are the tori
written as the distance function `sqrt((sqrt(x^2 + z^2) - R)^2 + y^2) - r`);
the teapot is the 32 patches of scenes/teapot.bpt, against meshes of 12x12
quads per patch (the SPD's size factor) and 32x32. Every mesh is tessellated per object so
that its chords stray at most a quarter of a pixel (at 512x512, at the
object's distance) from the surface, which is "the same look" at that
resolution: `--check OUT_DIR WHITTED [NAME ...]` prints how many pixels of depth images rendered from
the two disagree on hit or miss.
"""

import math
import random
import struct
import subprocess
import sys
from pathlib import Path

COUNT = 125
EYE = (0.0, 0.0, -20.0)
FOV = 40.0
SIDE = 512
# Largest distance, in pixels at SIDE x SIDE, of a chord from the surface.
TOLERANCE_PIXELS = 0.25
LIGHT = (-20.0, 30.0, -40.0)


def header(eye, look_at, up, fov):
    return (
        f"[camera]\neye = {fmt(eye)}\nlook_at = {fmt(look_at)}\nup = {fmt(up)}\nfov = {fov}\n\n"
        f'[[lights]]\ntype = "point"\nposition = {fmt(LIGHT)}\n'
    )


def nff_header(eye, look_at, up, fov):
    # NFF's angle spans the centres of the first and last pixel rows.
    half = math.tan(math.radians(fov) / 2) * (SIDE - 1) / SIDE
    angle = math.degrees(2 * math.atan(half))
    return (
        f"b 0 0 0\nv\nfrom {nums(eye)}\nat {nums(look_at)}\nup {nums(up)}\n"
        f"angle {angle:.12f}\nhither 0.01\nresolution {SIDE} {SIDE}\n"
        f"l {nums(LIGHT)}\nf 0.8 0.8 0.8 1 0 1 0 1\n"
    )


def fmt(v):
    return "[" + ", ".join(f"{x:.9g}" for x in v) + "]"


def nums(v):
    return " ".join(f"{x:.9g}" for x in v)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(s, a):
    return tuple(s * x for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def unit(a):
    return scale(1 / math.sqrt(dot(a, a)), a)


def rotation(axis, degrees):
    """The right-handed rotation matrix about `axis` (rows)."""
    x, y, z = unit(axis)
    a = math.radians(degrees)
    c, s, t = math.cos(a), math.sin(a), 1 - math.cos(a)
    return (
        (t * x * x + c, t * x * y - s * z, t * x * z + s * y),
        (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
        (t * x * z - s * y, t * y * z + s * x, t * z * z + c),
    )


def apply(m, v):
    return tuple(dot(row, v) for row in m)


def pixel_size(centre, fov=FOV, eye=EYE):
    """World size of one pixel at the distance of `centre`."""
    d = math.sqrt(dot(sub(centre, eye), sub(centre, eye)))
    return 2 * d * math.tan(math.radians(fov) / 2) / SIDE


def segments(radius, tolerance, least=6):
    """Segments of a circle of `radius` whose chords stray at most `tolerance`."""
    if radius <= tolerance:
        return least
    return max(least, math.ceil(math.pi / math.acos(1 - tolerance / radius)))


class Mesh:
    """Triangles with a normal at every corner, written as NFF `pp 3`."""

    def __init__(self):
        self.lines = []
        self.count = 0

    def grid(self, points, normals):
        """Two triangles per cell of a grid of rows of points."""
        for i in range(len(points) - 1):
            for j in range(len(points[0]) - 1):
                a, b, c, d = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
                self.triangle(points, normals, a, b, c)
                self.triangle(points, normals, a, c, d)

    def triangle(self, points, normals, *corners):
        ps = [points[i][j] for i, j in corners]
        area = cross(sub(ps[1], ps[0]), sub(ps[2], ps[0]))
        if dot(area, area) < 1e-24:
            return
        self.lines.append("pp 3\n")
        for (i, j), p in zip(corners, ps):
            n = normals[i][j]
            if dot(n, n) < 1e-24:
                n = unit(area)
            self.lines.append(f"{nums(p)} {nums(n)}\n")
        self.count += 1


def placements():
    """COUNT (centre, axis, angle, size, a, b) in a cube of side 10."""
    rng = random.Random(17)
    for _ in range(COUNT):
        centre = tuple(rng.uniform(-5, 5) for _ in range(3))
        axis = tuple(rng.gauss(0, 1) for _ in range(3))
        angle = rng.uniform(0, 180)
        size = rng.uniform(0.3, 0.8)
        yield centre, axis, angle, size, rng.uniform(0, 1), rng.uniform(0, 1)


def place(m, centre, p):
    return add(apply(m, p), centre)


def transform(axis, angle, centre):
    return (
        f"transform = [{{ rotate = {{ axis = {fmt(axis)}, angle = {angle:.6f} }} }}, "
        f"{{ translate = {fmt(centre)} }}]\n"
    )


def torus_grid(major, minor, m, centre, tolerance):
    nu = segments(major + minor, tolerance)
    nv = segments(minor, tolerance)
    points, normals = [], []
    for i in range(nu + 1):
        phi = 2 * math.pi * i / nu
        row_p, row_n = [], []
        for j in range(nv + 1):
            theta = 2 * math.pi * j / nv
            ring = major + minor * math.cos(theta)
            n = (math.cos(theta) * math.cos(phi), math.sin(theta), -math.cos(theta) * math.sin(phi))
            p = (ring * math.cos(phi), minor * math.sin(theta), -ring * math.sin(phi))
            row_p.append(place(m, centre, p))
            row_n.append(apply(m, n))
        points.append(row_p)
        normals.append(row_n)
    return points, normals


def tori(out, implicit):
    toml, mesh = [header(EYE, (0, 0, 0), (0, 1, 0), FOV)], Mesh()
    for centre, axis, angle, size, a, _ in placements():
        minor = size * (0.15 + 0.2 * a)
        major = size - minor
        if implicit:
            e = 1e-3 * size
            box = [(-size - e, -minor - e, -size - e), (size + e, minor + e, size + e)]
            toml.append(
                f'\n[[objects]]\nshape = "implicit"\n'
                f'function = "sqrt((sqrt(x^2 + z^2) - {major:.9g})^2 + y^2) - {minor:.9g}"\n'
                f"bounds = [{fmt(box[0])}, {fmt(box[1])}]\nmax_gradient = 1.0001\n"
            )
        else:
            toml.append(
                f'\n[[objects]]\nshape = "torus"\nmajor = {major:.9g}\nminor = {minor:.9g}\n'
            )
        toml.append(transform(axis, angle, centre))
        m = rotation(axis, angle)
        mesh.grid(*torus_grid(major, minor, m, centre, TOLERANCE_PIXELS * pixel_size(centre)))
    return toml, mesh


def ellipsoid_grid(radii, m, centre, tolerance):
    n = segments(max(radii), tolerance)
    points, normals = [], []
    for i in range(n // 2 + 1):
        theta = math.pi * i / (n // 2)
        row_p, row_n = [], []
        for j in range(n + 1):
            phi = 2 * math.pi * j / n
            s = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))
            p = tuple(r * x for r, x in zip(radii, s))
            g = tuple(x / r for r, x in zip(radii, s))
            row_p.append(place(m, centre, p))
            row_n.append(apply(m, g))
        points.append(row_p)
        normals.append(row_n)
    return points, normals


def spheres(out, quadric):
    toml, mesh = [header(EYE, (0, 0, 0), (0, 1, 0), FOV)], Mesh()
    identity = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    for centre, axis, angle, size, a, b in placements():
        tolerance = TOLERANCE_PIXELS * pixel_size(centre)
        if quadric:
            radii = (size, size * (0.4 + 0.6 * a), size * (0.4 + 0.6 * b))
            coefficients = "".join(
                f"{k} = {1 / (r * r):.9g}\n" for k, r in zip("abc", radii)
            )
            toml.append(f'\n[[objects]]\nshape = "quadric"\n{coefficients}j = -1\n')
            toml.append(transform(axis, angle, centre))
            mesh.grid(*ellipsoid_grid(radii, rotation(axis, angle), centre, tolerance))
        else:
            toml.append(
                f'\n[[objects]]\nshape = "sphere"\ncenter = {fmt(centre)}\nradius = {size:.9g}\n'
            )
            mesh.grid(*ellipsoid_grid((size,) * 3, identity, centre, tolerance))
    return toml, mesh


def superellipsoid_point(q, e, n):
    """The point of the unit superellipsoid on the ray from the centre through `q`."""
    x, y, z = (abs(c) for c in q)
    f = (x ** (2 / e) + y ** (2 / e)) ** (e / n) + z ** (2 / n)
    return scale(f ** (-n / 2), q)


def power(a, k):
    """`a ** k` for `a >= 0`, with 0 to a negative power taken as very large."""
    if a == 0:
        return 0.0 if k > 0 else (1.0 if k == 0 else 1e12)
    return a**k


def superellipsoid_normal(p, e, n):
    x, y, z = p
    xy = power(abs(x), 2 / e) + power(abs(y), 2 / e)
    outer = power(xy, e / n - 1)
    gx = outer * power(abs(x), 2 / e - 1) * math.copysign(1, x)
    gy = outer * power(abs(y), 2 / e - 1) * math.copysign(1, y)
    gz = power(abs(z), 2 / n - 1) * math.copysign(1, z)
    g = (gx, gy, gz)
    size = math.sqrt(dot(g, g))
    return scale(1 / size, g) if size > 0 and math.isfinite(size) else (0.0, 0.0, 0.0)


def superellipsoids(out):
    toml, mesh = [header(EYE, (0, 0, 0), (0, 1, 0), FOV)], Mesh()
    for centre, _, _, size, a, b in placements():
        e, n = 0.2 + 2.8 * a, 0.2 + 2.8 * b
        toml.append(
            f'\n[[objects]]\nshape = "superellipsoid"\ne = {e:.9g}\nn = {n:.9g}\n'
            f"center = {fmt(centre)}\nradius = {size:.9g}\n"
        )
        # A cube's faces, each an N x N grid, carried along the rays from
        # the centre onto the surface. The sharpest rounding (exponents near
        # 0.2, and the points of stars) needs about π times a sphere's
        # sampling per unit of length.
        tolerance = TOLERANCE_PIXELS * pixel_size(centre)
        cells = segments(size, tolerance)
        for axis in range(3):
            for sign in (-1, 1):
                points, normals = [], []
                for i in range(cells + 1):
                    row_p, row_n = [], []
                    for j in range(cells + 1):
                        u, v = -1 + 2 * i / cells, -1 + 2 * j / cells
                        q = [0.0, 0.0, 0.0]
                        q[axis] = sign
                        q[(axis + 1) % 3] = u if sign > 0 else v
                        q[(axis + 2) % 3] = v if sign > 0 else u
                        p = superellipsoid_point(q, e, n)
                        row_p.append(add(scale(size, p), centre))
                        row_n.append(superellipsoid_normal(p, e, n))
                    points.append(row_p)
                    normals.append(row_n)
                mesh.grid(points, normals)
    return toml, mesh


def bezier(points, u, v):
    """The point and normal of a bicubic patch (4 rows of 4) at (u, v)."""

    def basis(t):
        s = 1 - t
        return (s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t), (
            -3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t)

    (bu, du), (bv, dv) = basis(u), basis(v)

    def combine(wu, wv):
        return tuple(
            sum(wu[i] * wv[j] * points[i][j][k] for i in range(4) for j in range(4))
            for k in range(3)
        )

    return combine(bu, bv), cross(combine(du, bv), combine(bu, dv))


def teapot(out, quads):
    words = (Path(__file__).parent.parent / "scenes" / "teapot.bpt").read_text().split()
    count, at = int(words[0]), 1
    eye, look_at, up, fov = (8.0, -10.0, 6.0), (0.0, 0.0, 1.5), (0.0, 0.0, 1.0), 40.0
    toml = [header(eye, look_at, up, fov)]
    toml.append('\n[[objects]]\nshape = "patches"\nfile = "teapot.bpt"\n')
    mesh = Mesh()
    for _ in range(count):
        at += 2
        flat = [tuple(float(w) for w in words[at + 3 * k : at + 3 * k + 3]) for k in range(16)]
        at += 48
        rows = [flat[4 * i : 4 * i + 4] for i in range(4)]
        points, normals = [], []
        for i in range(quads + 1):
            row_p, row_n = [], []
            for j in range(quads + 1):
                u, v = i / quads, j / quads
                p, n = bezier(rows, u, v)
                if dot(n, n) < 1e-20:
                    # A collapsed row: the normal is the limit from inside.
                    _, n = bezier(rows, min(max(u, 1e-4), 1 - 1e-4), min(max(v, 1e-4), 1 - 1e-4))
                row_p.append(p)
                row_n.append(n)
            points.append(row_p)
            normals.append(row_n)
        mesh.grid(points, normals)
    (out / "teapot.bpt").write_text((Path(__file__).parent.parent / "scenes" / "teapot.bpt").read_text())
    return toml, mesh, nff_header(eye, look_at, up, fov)


def write(out, name, toml, mesh, nff=None):
    (out / f"{name}.toml").write_text("".join(toml))
    with open(out / f"{name}-mesh.nff", "w") as f:
        f.write(nff or nff_header(EYE, (0, 0, 0), (0, 1, 0), FOV))
        f.writelines(mesh.lines)
    print(f"{name}: {mesh.count} triangles")


def read_pfm(path):
    """The values of a one-channel PFM image, row by row."""
    data = path.read_bytes()
    parts = data.split(b"\n", 3)
    width, height = (int(w) for w in parts[1].split())
    little = float(parts[2]) < 0
    count = width * height * (3 if parts[0].strip() == b"PF" else 1)
    values = struct.unpack(("<" if little else ">") + f"{count}f", parts[3][: 4 * count])
    return values[:: (3 if parts[0].strip() == b"PF" else 1)]


def check(out, names, whitted):
    """Renders depth from both scenes of each pair; prints how many pixels
    disagree on hit or miss (and how many of those lie next to a pixel
    where the exact shape's depth jumps: silhouettes)."""
    for name in names:
        depths = []
        for scene in (f"{name}.toml", f"{name}-mesh.nff"):
            image = out / f"{scene}.pfm"
            subprocess.run(
                [whitted, "render", str(out / scene), "-o", str(out / f"{scene}.png"),
                 "--width", str(SIDE), "--height", str(SIDE), "--aov", f"depth={image}"],
                check=True, capture_output=True)
            depths.append(read_pfm(image))
        exact, mesh = depths
        hit = [math.isfinite(d) and d > 0 for d in exact]
        mesh_hit = [math.isfinite(d) and d > 0 for d in mesh]
        differ = [k for k in range(len(hit)) if hit[k] != mesh_hit[k]]

        def on_edge(k):
            y, x = divmod(k, SIDE)
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    yy, xx = y + dy, x + dx
                    if 0 <= yy < SIDE and 0 <= xx < SIDE and hit[yy * SIDE + xx] != hit[k]:
                        return True
            return False

        inner = [k for k in differ if not on_edge(k)]
        both = [k for k in range(len(hit)) if hit[k] and mesh_hit[k]]
        worst = max((abs(exact[k] - mesh[k]) / exact[k] for k in both), default=0.0)
        print(f"{name}: {sum(hit)} pixels hit, {len(differ)} differ on hit or miss "
              f"({len(inner)} not next to a silhouette), "
              f"largest relative depth difference {worst:.2e}")


def main():
    if sys.argv[1:2] == ["--check"]:
        out = Path(sys.argv[2])
        check(out, sys.argv[4:] or ["spheres", "quadrics", "tori", "implicit-tori",
                                    "superellipsoids", "teapot-12", "teapot-32"], sys.argv[3])
        return
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/shape-mesh-bench")
    out.mkdir(parents=True, exist_ok=True)
    write(out, "spheres", *spheres(out, quadric=False))
    write(out, "quadrics", *spheres(out, quadric=True))
    write(out, "tori", *tori(out, implicit=False))
    write(out, "implicit-tori", *tori(out, implicit=True))
    write(out, "superellipsoids", *superellipsoids(out))
    for quads in (12, 32):
        toml, mesh, nff = teapot(out, quads)
        write(out, f"teapot-{quads}", toml, mesh, nff)


if __name__ == "__main__":
    main()
