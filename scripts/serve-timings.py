#!/usr/bin/env python3
"""Times `whitted serve`: from a change of camera posted to the first
(coarse) frame and to the full frame pushed back, as a page sees them.

    python3 scripts/serve-timings.py target/release/whitted [SCENE] [ARGS...]

Starts the server on a free port, waits for its first full frame, then
moves the camera 5 times (two eyes in turn) and prints the median times.
"""
import json
import socket
import statistics
import subprocess
import sys
import time


def events(port):
    s = socket.create_connection(("127.0.0.1", port))
    s.sendall(f"GET /events HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
    f = s.makefile("rb")
    while f.readline() not in (b"\r\n", b""):
        pass
    name = None
    for line in f:
        line = line.decode().rstrip("\n")
        if line.startswith("event: "):
            name = line[7:]
        elif line.startswith("data: "):
            yield name, json.loads(line[6:])


def post(port, form):
    s = socket.create_connection(("127.0.0.1", port))
    s.sendall(
        f"POST /api/view HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
        f"Content-Length: {len(form)}\r\n\r\n{form}".encode()
    )
    answer = s.recv(100)
    assert answer.startswith(b"HTTP/1.1 200"), answer


def main():
    server = subprocess.Popen(
        [sys.argv[1], "serve", *sys.argv[2:], "--port", "0"], stdout=subprocess.PIPE
    )
    try:
        line = server.stdout.readline().decode()
        port = int(line.split("127.0.0.1:")[1].split("/")[0])
        stream = events(port)
        build = 0.0
        for name, data in stream:
            if name == "error":
                sys.exit(data["message"])
            build += data.get("build_seconds", 0.0)
            if data.get("pass") == "full":
                eye = data["state"]["camera"]["eye"]
                last = data["request"]
                print(f"{data['width']}x{data['height']}, {data['accel']}: "
                      f"build {build * 1e3:.1f} ms (the first view's passes)")
                break
        coarse, full = [], []
        for i in range(5):
            moved = [e * (1.1 if i % 2 == 0 else 1.0) for e in eye]
            start = time.perf_counter()
            post(port, "eye=" + ",".join(map(str, moved)))
            for name, data in stream:
                if name != "frame" or data["request"] <= last:
                    continue
                if data["pass"] == "coarse":
                    coarse.append(time.perf_counter() - start)
                if data["pass"] == "full":
                    full.append(time.perf_counter() - start)
                    last = data["request"]
                    break
        print(f"first (coarse, 1/8) frame: {statistics.median(coarse) * 1e3:.0f} ms; "
              f"full frame: {statistics.median(full) * 1e3:.0f} ms (medians of 5)")
    finally:
        server.kill()


main()
