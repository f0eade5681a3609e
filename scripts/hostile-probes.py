#!/usr/bin/env python3
"""Runs the worst probe of each defect class of a hostile-input audit
(issue 23, or with --round 3 issue 50) against one `whitted` binary and
prints a table: exit code, wall time, peak resident memory and the first
line of what it said. Round 3 then probes `whitted serve` (slow clients,
event streams, HEAD, Host headers, long heads, another bound address) and
prints a second table with the server's peak memory.

    python3 scripts/hostile-probes.py target/release/whitted [--round 3]

Each probe runs in a fresh temporary folder, killed after --timeout seconds
(default 60) and limited to --max-gib GiB of address space (default 16), so
that an old binary's runaway cases end instead of taking the machine. The
hostile test suite (crates/whitted-cli/tests/hostile) asserts the outcomes;
this script only measures them, for the figures in the issue's note.
"""

import argparse
import os
import resource
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
import zlib

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GLASS_IN_MIRRORS = os.path.join(REPOSITORY, "crates/whitted/tests/hostile_scenes/glass_in_mirrors.toml")

SCENE_HEAD = """
[camera]
eye = [0, 0, -5]
look_at = [0, 0, 0]
[materials.m]
diffuse = 0.5
[[lights]]
type = "point"
position = [0, 5, -5]
intensity = 1
"""


def big_png(width, height):
    """A PNG of width x height black RGB pixels, whole and valid: its
    deflated rows are about a thousandth of their size. Built once and
    kept in the temporary folder (about 5 MB for 40000 x 40000)."""
    cache = os.path.join(tempfile.gettempdir(), f"whitted-probe-{width}x{height}.png")
    if os.path.exists(cache):
        with open(cache, "rb") as f:
            return f.read()

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    deflate = zlib.compressobj(9)
    row = b"\0" * (1 + 3 * width)
    rows_per_piece = max(1, (1 << 24) // len(row))
    pieces = []
    for start in range(0, height, rows_per_piece):
        pieces.append(deflate.compress(row * min(rows_per_piece, height - start)))
    pieces.append(deflate.flush())
    data = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
        + chunk(b"IDAT", b"".join(pieces))
        + chunk(b"IEND", b"")
    )
    with open(cache, "wb") as f:
        f.write(data)
    return data


def write(folder, name, data):
    path = os.path.join(folder, name)
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(path, mode) as f:
        f.write(data)
    return path


def setup_texture(d):
    write(d, "big.png", big_png(40000, 40000))
    write(
        d,
        "t.toml",
        SCENE_HEAD.replace('diffuse = 0.5', 'diffuse = { image = "big.png" }')
        + '[[objects]]\nshape = "sphere"\ncenter = [0,0,0]\nradius = 1\nmaterial = "m"\n',
    )


def setup_zero(d):
    os.symlink("/dev/zero", os.path.join(d, "zero.obj"))


def setup_mirrors(d):
    with open(GLASS_IN_MIRRORS) as f:
        write(d, "m.toml", f.read())


def setup_usemtl(d):
    lines = ["v 0 0 0", "v 1 0 0", "v 0 1 0"]
    for i in range(200000):
        lines.append(f"usemtl m{i}")
        lines.append("f 1 2 3")
    write(d, "many.obj", "\n".join(lines) + "\n")


def setup_flat(d):
    write(d, "flat.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")


def setup_bom(d):
    write(d, "bom.obj", b"\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")


def setup_kd(d):
    write(d, "k.mtl", "newmtl m\nKd -1 -1 -1\n")
    write(d, "k.obj", "mtllib k.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n")


def setup_light(d):
    write(
        d,
        "l.toml",
        SCENE_HEAD.replace("intensity = 1", "intensity = 1e39")
        + '[[objects]]\nshape = "sphere"\ncenter = [0,0,0]\nradius = 1\nmaterial = "m"\n',
    )


def setup_huge_sphere(d):
    write(
        d,
        "s.toml",
        SCENE_HEAD
        + '[[objects]]\nshape = "sphere"\ncenter = [0,0,0]\nradius = 2e154\nmaterial = "m"\n',
    )


def setup_bow_tie(d):
    write(
        d,
        "b.toml",
        SCENE_HEAD
        + '[[objects]]\nshape = "polygon"\nvertices = [[-1,-1,0],[1,1,0],[1,-1,0],[-1,1,0]]\n'
        'material = "m"\n',
    )


def setup_scale(d):
    write(
        d,
        "sc.toml",
        SCENE_HEAD
        + '[[objects]]\nshape = "sphere"\ncenter = [0,0,0]\nradius = 1\nmaterial = "m"\n'
        "transform = [{ scale = 1e103 }]\n",
    )


def setup_big_obj(d):
    n = 1000
    lines = []
    for j in range(n + 1):
        for i in range(n + 1):
            lines.append(f"v {i} {j} {(i * j) % 7}")
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i + 1
            lines.append(f"f {a} {a + 1} {a + n + 2}")
            lines.append(f"f {a} {a + n + 2} {a + n + 1}")
    write(d, "big.obj", "\n".join(lines) + "\n")


def setup_nan_rays(d):
    os.mkdir(os.path.join(d, "rays"))
    write(d, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    # 32-byte records: u32 pixel, origin, direction, t_far; a NaN origin.
    rays = struct.pack("<I7f", 0, float("nan"), 0, 0, 0, 0, 1, float("inf"))
    for kind in ("primary", "diffuse"):
        write(d, f"rays/{kind}.rays", rays)
        write(d, f"rays/{kind}.hits", struct.pack("<fI", -1.0, 0xFFFFFFFF))
    write(d, "rays/shadow.rays", rays)
    write(d, "rays/shadow.hits", b"\0")


def setup_triangle(d):
    write(d, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")


def setup_outputs(d):
    write(d, "a.pfm", "old")


PROBES = [
    # (item, what, setup, args, special)
    ("1", "render to a closed pipe", None, ["render", "-o", "y.png", "--width", "64", "--height", "48"], "closed-pipe"),
    ("2", "bench 65535x65535", setup_triangle, ["bench", "tri.obj", "--width", "65535", "--height", "65535"], None),
    ("3", "40000² PNG texture", setup_texture, ["render", "t.toml", "--width", "32", "--height", "24"], None),
    ("4", "scene -> /dev/zero", setup_zero, ["render", "zero.obj"], None),
    ("5", "16384² with 4 AOVs", None, ["render", "--width", "16384", "--height", "16384", "--aov", "depth=d.exr",
                                        "--aov", "normal=n.exr", "--aov", "id=i.exr", "--aov", "cost=c.exr"], None),
    ("6", "--threads 100000", None, ["render", "--width", "64", "--height", "48", "--threads", "100000"], None),
    ("7", "glass in mirrors, depth 40", setup_mirrors, ["render", "m.toml", "--width", "32", "--height", "24"], None),
    ("8", "200000 usemtl, --quiet", setup_usemtl, ["render", "many.obj", "--quiet", "--width", "32", "--height", "24"], None),
    ("10", "-o a.pfm --aov depth=./a.pfm", setup_outputs, ["render", "-o", "a.pfm", "--aov", "depth=./a.pfm"], None),
    ("11", "SIGINT while writing", None, ["render", "--width", "2000", "--height", "2000", "-o", "x.exr"], "sigint"),
    ("12", "unwritable folder", None, ["render", "-o", "/proc/x.png"], None),
    ("13", "flat OBJ quad", setup_flat, ["render", "flat.obj", "-o", "f.pfm", "--width", "32", "--height", "24"], None),
    ("14", "BOM in OBJ", setup_bom, ["render", "bom.obj", "--width", "32", "--height", "24"], None),
    ("15", "MTL Kd -1", setup_kd, ["render", "k.obj", "--width", "32", "--height", "24"], None),
    ("16", "light intensity 1e39", setup_light, ["render", "l.toml", "-o", "l.pfm", "--width", "32", "--height", "24"], None),
    ("17", "sphere radius 2e154", setup_huge_sphere, ["render", "s.toml", "--width", "32", "--height", "24"], None),
    ("18", "bow-tie polygon", setup_bow_tie, ["render", "b.toml", "--width", "32", "--height", "24"], None),
    ("19", "scale = 1e103", setup_scale, ["render", "sc.toml"], None),
    ("19", "--width -1", None, ["render", "--width", "-1"], None),
    ("20", "--width 0 with a big OBJ", setup_big_obj, ["render", "big.obj", "--width", "0"], None),
    ("21", "NaN rays", setup_nan_rays, ["bench", "tri.obj", "--rays", "rays", "--runs", "1"], None),
    ("21", "--eye 3e38,3e38,3e38", None, ["render", "--eye", "3e38,3e38,3e38", "--width", "64", "--height", "48"], None),
    ("also", "samples 4294967295 on 1x1", None, ["render", "--width", "1", "--height", "1", "--spp", "4294967295"], None),
]


SPHERE = '[[objects]]\nshape = "sphere"\ncenter = [0,0,0]\nradius = 1\nmaterial = "m"\n'


def setup_output_over_texture(d):
    write(d, "tex.png", big_png(64, 64))
    write(d, "t.toml", SCENE_HEAD.replace("diffuse = 0.5", 'diffuse = { image = "tex.png" }') + SPHERE)


def setup_rect_mirrors(d):
    with open(os.path.join(REPOSITORY, "crates/whitted/tests/hostile_scenes/glass_in_mirrors_area_light.toml")) as f:
        write(d, "m.toml", f.read())


def setup_wrapping_count(d):
    text = SCENE_HEAD + '[[objects]]\nshape = "plane"\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\nmaterial = "m"\n'
    text += '[definitions.d0]\nobjects = [{ shape = "sphere", radius = 0.1, material = "m" }]\n'
    for level in range(1, 8):
        placements = ", ".join([f'{{ instance = "d{level - 1}" }}'] * 256)
        text += f"[definitions.d{level}]\nobjects = [{placements}]\n"
    text += '[[objects]]\ninstance = "d7"\n' * 256
    write(d, "w.toml", text)


def setup_three_textures(d):
    write(d, "a.png", big_png(7000, 7000))
    write(d, "b.png", big_png(7001, 7000))
    write(d, "c.png", big_png(7002, 7000))
    write(
        d,
        "x.toml",
        SCENE_HEAD.replace(
            "diffuse = 0.5",
            'diffuse = { image = "a.png" }\nspecular = { image = "b.png" }\n'
            'bump_map = { image = "c.png" }',
        )
        + SPHERE,
    )


def setup_patches(d):
    state = 12345
    lines = ["100000"]
    for p in range(100000):
        lines.append("3 3")
        for _ in range(16):
            coords = []
            for _ in range(3):
                state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
                coords.append((state >> 11) / (1 << 53))
            lines.append(f"{coords[0] + p % 20} {coords[1] + p // 20 % 50} {coords[2]}")
    write(d, "crumpled.bpt", "\n".join(lines) + "\n")


def setup_nff_line(d):
    spheres = " ".join(f"s {i % 100} {i // 100} 0 0.4" for i in range(200000))
    write(d, "line.nff", "v\nfrom 0 0 -10\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\n"
          "resolution 32 24\nl 0 10 -10\nf 1 1 1 1 0 0 0 1\n" + spheres + "\n")


def setup_slow_implicit(d):
    with open(os.path.join(REPOSITORY, "crates/whitted/tests/hostile_scenes/slow_implicit.toml")) as f:
        write(d, "i.toml", f.read())


def setup_long_name(d):
    name = "n" * 10_000_000
    write(d, "long.toml", SCENE_HEAD + SPHERE.replace('material = "m"', f'material = "{name}"'))


def setup_utf16(d):
    write(d, "u.toml", "\ufeff[camera]\n".encode("utf-16-le"))


def setup_mtl_dissolve(d):
    write(d, "d.mtl", "newmtl m\nKd 1 1 1\nd -1\nTr 2\nNs -5\n")
    write(d, "d.obj", "mtllib d.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n")


def setup_huge_number(d):
    write(d, "h.toml", SCENE_HEAD + SPHERE.replace("radius = 1", "radius = -1e300"))


def setup_grid_model(d):
    n = 600
    lines = [f"v {i} {j} {(i * j) % 3}" for i in range(n) for j in range(n)]
    for i in range(n - 1):
        for j in range(n - 1):
            a = i * n + j + 1
            lines.append(f"f {a} {a + 1} {a + n}")
            lines.append(f"f {a + 1} {a + n + 1} {a + n}")
    write(d, "grid.obj", "\n".join(lines) + "\n")


def setup_vertices(d):
    write(d, "verts.obj", "v 1 2 3\n" * 2_000_000 + "f 1 2 3\n")


# Issue 50 (round 3): the worst probe of each class that a command line can
# reach; the server's (20-22) are SERVE_PROBES_3 below; item 4 and the races
# and full disks (11, 13) are measured by their tests.
PROBES_3 = [
    ("1", "-o over the scene's texture", setup_output_over_texture, ["render", "t.toml", "-o", "tex.png"], None),
    ("2", "explain, 4096-sample light in mirrors", setup_rect_mirrors, ["explain", "m.toml", "--pixel", "4,4", "--json", "-q"], None),
    ("3", "256^8 placements + a plane", setup_wrapping_count, ["render", "w.toml"], None),
    ("5", "three 7000² textures, --max-memory 1G", setup_three_textures, ["render", "x.toml", "--max-memory", "1G", "--width", "32", "--height", "24"], None),
    ("5", "718k-triangle grid, kd-tree, --max-memory 256M", setup_grid_model, ["render", "grid.obj", "--accel", "kdtree", "--max-memory", "256M", "--width", "32", "--height", "24"], None),
    ("6", "16384² under ulimit -v 4G", None, ["render", "--width", "16384", "--height", "16384", "-o", "big.png"], "ulimit-v-4G"),
    ("6", "16384², --max-memory 64G, ulimit -v 2G", None, ["render", "--width", "16384", "--height", "16384", "--max-memory", "64G", "-o", "big.png"], "ulimit-v-2G"),
    ("6", "718k-triangle kd-tree, --max-memory 64G, ulimit -v 300M", setup_grid_model, ["render", "grid.obj", "--accel", "kdtree", "--max-memory", "64G", "--width", "8", "--height", "8"], "ulimit-v-300M"),
    ("5", "bench, 2M vertices, --max-memory 24M", setup_vertices, ["bench", "verts.obj", "--width", "16", "--height", "16", "--max-memory", "24M"], None),
    ("7", "100,000 crumpled patches, --max-memory 256M", setup_patches, ["render", "crumpled.bpt", "--max-memory", "256M", "--width", "64", "--height", "48"], None),
    ("9", "NFF, 200,000 spheres on one line", setup_nff_line, ["render", "line.nff", "--width", "32", "--height", "24"], None),
    ("10", "implicit, max_gradient 1e30", setup_slow_implicit, ["render", "i.toml"], None),
    ("12", "-o x.exr under ulimit -f 200", None, ["render", "--width", "2000", "--height", "2000", "-o", "x.exr"], "ulimit-f-200K"),
    ("14", "explain >&-", None, ["explain", "--pixel", "1,1"], "closed-stdout"),
    ("16", "10 MB material name", setup_long_name, ["render", "long.toml"], None),
    ("17", "UTF-16 scene", setup_utf16, ["render", "u.toml"], None),
    ("18", "MTL d -1, Tr 2, Ns -5", setup_mtl_dissolve, ["render", "d.obj", "--width", "32", "--height", "24"], None),
    ("19", "radius -1e300", setup_huge_number, ["render", "h.toml"], None),
]


def build_in_child(setup, folder):
    """Runs `setup` in a forked child, so that this process stays small: a
    child's peak memory (ru_maxrss) starts at its parent's size when forked."""
    pid = os.fork()
    if pid == 0:
        try:
            setup(folder)
        finally:
            os._exit(0)
    os.waitpid(pid, 0)


def limit(max_bytes, special=None):
    def apply():
        address_space = max_bytes
        if special == "ulimit-v-4G":
            address_space = 4 << 30
        elif special == "ulimit-v-2G":
            address_space = 2 << 30
        elif special == "ulimit-v-300M":
            address_space = 300 << 20
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))
        if special == "ulimit-f-200K":
            resource.setrlimit(resource.RLIMIT_FSIZE, (200 << 10, 200 << 10))
        if special == "closed-stdout":
            os.close(1)
        os.setsid()

    return apply


def run(binary, folder, args, special, timeout, max_bytes):
    before = set(os.listdir(folder))
    start = time.monotonic()
    err_path = os.path.join(folder, ".stderr")
    with open(err_path, "wb") as err:
        if special == "closed-pipe":
            reader, writer = os.pipe()
            os.close(reader)
            proc = subprocess.Popen([binary] + args, cwd=folder, stdout=writer, stderr=writer,
                                    stdin=subprocess.DEVNULL, preexec_fn=limit(max_bytes))
            os.close(writer)
        else:
            proc = subprocess.Popen([binary] + args, cwd=folder, stdout=err, stderr=err,
                                    stdin=subprocess.DEVNULL, preexec_fn=limit(max_bytes, special))
    killed = False
    signalled = False
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        elapsed = time.monotonic() - start
        writing = special == "sigint" and any(n.endswith(".partial") for n in os.listdir(folder))
        if special == "sigint" and not signalled and (writing or elapsed > 20):
            os.kill(proc.pid, signal.SIGINT)
            signalled = True
        if elapsed > timeout and not killed:
            os.killpg(proc.pid, signal.SIGKILL)
            killed = True
        time.sleep(0.01)
    seconds = time.monotonic() - start
    if os.WIFEXITED(status):
        outcome = f"exit {os.WEXITSTATUS(status)}"
    else:
        outcome = f"signal {os.WTERMSIG(status)}"
    if killed:
        outcome += f" (killed at {timeout} s)"
    with open(err_path, "rb") as f:
        said = f.read().decode("utf-8", "replace")
    lines = [line for line in said.splitlines() if line.strip()]
    first = lines[0] if lines else ""
    if len(first) > 110:
        first = first[:107] + "..."
    if special == "sigint" and not signalled:
        outcome += " (ended before the signal)"
    partials = [n for n in os.listdir(folder) if n.endswith(".partial")]
    if partials:
        outcome += f", {len(partials)} .partial left"
    written = sorted(set(os.listdir(folder)) - before - {".stderr"})
    return outcome, seconds, usage.ru_maxrss / 1024, first, len(said), ", ".join(written)


class Server:
    """`whitted serve` of the built-in scene on a free port of `bind`."""

    def __init__(self, binary, bind="127.0.0.1"):
        self.proc = subprocess.Popen(
            [binary, "serve", "--port", "0", "--bind", bind, "--width", "64", "--height", "48"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        # Nothing more is read from it: the server prints only this line.
        self.proc.stdout.close()
        if "http://" not in line:
            self.proc.kill()
            raise RuntimeError(f"whitted serve printed no address: {line!r}")
        address = line.split("http://", 1)[1].split("/", 1)[0]
        self.host, port = address.rsplit(":", 1)
        self.port = int(port)

    def connect(self, timeout=30):
        return socket.create_connection((self.host, self.port), timeout=timeout)

    def exchange(self, head, timeout=30):
        """Sends a request head and reads the whole answer (the server closes
        after one): its status and the bytes after its head."""
        with self.connect(timeout) as s:
            s.sendall(head)
            answer = b""
            try:
                while chunk := s.recv(65536):
                    answer += chunk
                    if b"text/event-stream" in answer:
                        break
            except ConnectionResetError:
                # A refusal may close before reading what was sent.
                pass
        status = int(answer.split(b" ", 2)[1]) if answer.startswith(b"HTTP/") else 0
        return status, len(answer.split(b"\r\n\r\n", 1)[-1]) if b"\r\n\r\n" in answer else 0

    def get(self, path="/", extra=b""):
        return self.exchange(b"GET " + path.encode() + b" HTTP/1.1\r\nHost: "
                             + f"{self.host}:{self.port}".encode() + b"\r\n" + extra + b"\r\n")

    def peak_mib(self):
        with open(f"/proc/{self.proc.pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
        return float("nan")

    def stop(self):
        self.proc.terminate()
        self.proc.wait()


def probe_slow_clients(server, count):
    """Item 20: `count` connections sending their request head a byte every
    second; when a page is first answered with 200, and what the slow ones
    get."""
    slow = []
    for _ in range(count):
        s = server.connect()
        s.sendall(b"G")
        slow.append(s)
    start = time.monotonic()
    statuses = []
    while time.monotonic() - start < 20:
        status, _ = server.get("/")
        statuses.append(status)
        if status == 200:
            break
        for s in slow:
            try:
                s.sendall(b"E")
            except OSError:
                pass
        time.sleep(1)
    answered = time.monotonic() - start
    timed_out = 0
    for s in slow:
        s.settimeout(15)
        try:
            while True:
                s.sendall(b"E")
                answer = s.recv(64)
                if answer.startswith(b"HTTP/1.1 408"):
                    timed_out += 1
                if answer:
                    break
                time.sleep(1)
        except OSError:
            pass
        s.close()
    refused = sum(1 for st in statuses if st == 503)
    return (f"page 200 after {answered:.1f} s ({refused} tries answered 503 first); "
            f"{timed_out} of {count} slow heads answered 408")


def probe_event_streams(server):
    """Item 20: 64 event streams held open, then a page."""
    streams, refused = [], 0
    for _ in range(64):
        s = server.connect()
        s.sendall(b"GET /events HTTP/1.1\r\nHost: " + f"{server.host}:{server.port}".encode() + b"\r\n\r\n")
        head = s.recv(4096)
        if head.startswith(b"HTTP/1.1 503"):
            refused += 1
            s.close()
        else:
            streams.append(s)
    start = time.monotonic()
    status, _ = server.get("/")
    answered = time.monotonic() - start
    for s in streams:
        s.close()
    return f"{len(streams)} streams open, {refused} answered 503; page {status} in {answered * 1000:.0f} ms"


def probe_other_bind(binary):
    """Item 21: a server bound to 127.0.0.2 answers requests naming it."""
    server = Server(binary, "127.0.0.2")
    try:
        status, _ = server.get("/")
        return f"GET / with Host 127.0.0.2: {status}", server.peak_mib()
    finally:
        server.stop()


def probe_head(server):
    status, body = server.exchange(b"HEAD / HTTP/1.1\r\nHost: " + f"{server.host}:{server.port}".encode() + b"\r\n\r\n")
    return f"HEAD /: {status}, {body} body bytes"


def probe_two_hosts(server):
    status, _ = server.get("/", b"Host: evil.example\r\n")
    return f"a second Host: {status}"


def probe_long_head(server):
    status, _ = server.get("/", b"X-Pad: " + b"a" * (17 << 10) + b"\r\n")
    return f"a 17 KiB head: {status}"


SERVE_PROBES_3 = [
    ("20", "70 slow request heads", lambda server: probe_slow_clients(server, 70)),
    ("20", "300 slow request heads", lambda server: probe_slow_clients(server, 300)),
    ("20", "64 event streams", probe_event_streams),
    ("22", "HEAD /", probe_head),
    ("22", "two Host headers", probe_two_hosts),
    ("22", "17 KiB request head", probe_long_head),
]


def serve_probes(binary):
    """The server's probes of round 3, each on a fresh server, with the time
    it took and the server's peak resident memory."""
    print()
    print("| item | probe | outcome | time | server peak |")
    print("|---|---|---|---|---|")
    for item, what, probe in SERVE_PROBES_3:
        server = Server(binary)
        try:
            start = time.monotonic()
            outcome = probe(server)
            seconds = time.monotonic() - start
            print(f"| {item} | {what} | {outcome} | {seconds:.2f} s | {server.peak_mib():.0f} MiB |")
        finally:
            server.stop()
        sys.stdout.flush()
    start = time.monotonic()
    outcome, peak = probe_other_bind(binary)
    print(f"| 21 | --bind 127.0.0.2 | {outcome} | {time.monotonic() - start:.2f} s | {peak:.0f} MiB |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("--timeout", type=float, default=60)
    parser.add_argument("--max-gib", type=float, default=16)
    parser.add_argument("--round", type=int, choices=(2, 3), default=2,
                        help="the audit's probes: 2 for issue 23's (default), 3 for issue 50's")
    options = parser.parse_args()
    binary = os.path.realpath(options.binary)
    max_bytes = int(options.max_gib * (1 << 30))
    print("| item | probe | outcome | time | peak | new files | stderr bytes | first line said |")
    print("|---|---|---|---|---|---|---|---|")
    for item, what, setup, args, special in PROBES if options.round == 2 else PROBES_3:
        with tempfile.TemporaryDirectory() as folder:
            if setup:
                build_in_child(setup, folder)
            outcome, seconds, peak_mib, first, said, written = run(
                binary, folder, args, special, options.timeout, max_bytes
            )
        first = first.replace("|", "\\|")
        print(
            f"| {item} | {what} | {outcome} | {seconds:.2f} s | {peak_mib:.0f} MiB | {written} "
            f"| {said} | `{first}` |"
        )
        sys.stdout.flush()
    if options.round == 3:
        serve_probes(binary)


if __name__ == "__main__":
    main()
