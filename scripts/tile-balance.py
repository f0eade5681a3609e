#!/usr/bin/env python3
"""Load balance of a frame split in N parts: renders each part on one
thread and prints the CPU time of each, and the slowest over the mean, for
whitted's tiles (--tile I/N, interleaved rows) and for plain horizontal
bands (--crop of N bands of rows). CPU time (user + system, from wait4),
not wall time, so other work on the machine counts less.

    python3 scripts/tile-balance.py BINARY N WIDTH HEIGHT [SCENE] [RENDER OPTIONS...]
"""

import os
import subprocess
import sys
import tempfile


def cpu_seconds(args):
    process = subprocess.Popen(args)
    _, status, usage = os.wait4(process.pid, 0)
    if status != 0:
        sys.exit(f"{' '.join(args)} failed")
    return usage.ru_utime + usage.ru_stime


def main():
    binary, count, width, height, *rest = sys.argv[1:]
    count, width, height = int(count), int(width), int(height)
    base = [binary, "render", *rest, "--width", str(width), "--height", str(height),
            "--threads", "1", "--quiet"]
    with tempfile.TemporaryDirectory() as folder:
        part = os.path.join(folder, "part.wpart")
        ways = {
            "tiles": [["--tile", f"{i}/{count}"] for i in range(count)],
            "bands": [["--crop", f"0,{i * height // count},{width},{(i + 1) * height // count}"]
                      for i in range(count)],
        }
        for name, selections in ways.items():
            times = [cpu_seconds(base + selection + ["-o", part]) for selection in selections]
            mean = sum(times) / len(times)
            print(f"{name}: " + " ".join(f"{t:.2f}" for t in times)
                  + f" s; slowest/mean {max(times) / mean:.3f}")


if __name__ == "__main__":
    main()
