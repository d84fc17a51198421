#!/usr/bin/env python3
"""Memory and time of reading a big mesh, as a text trianglemesh and as a binary PLY.

Writes an N x N vertex grid (2 (N-1)^2 triangles) both ways and runs
`tessera info` on each, which reports what reading the files took at its
peak and what the built scene holds, both above what the process held
before. Prints per file: its size, the peak while reading as a multiple of
the mesh's own arrays (positions and indices, 4 bytes a number), the built
scene, and the seconds `info` took.

    python3 scripts/bench_mesh_load.py [--grid 1000] [--binary build/tessera]
"""
import argparse
import os
import random
import re
import struct
import subprocess
import sys
import tempfile
import time

HEADER = ('LookAt 0 5 -5 0 0 0 0 1 0\nCamera "perspective"\nWorldBegin\n'
          'LightSource "point" "point3 from" [0 3 0] "rgb I" [10 10 10]\n')


def grid(n):
    rnd = random.Random(1)
    points = [(i / n * 4 - 2, rnd.random() * 0.01, j / n * 4 - 2) for j in range(n) for i in range(n)]
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            tris += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    return points, tris


def write_text(path, points, tris):
    with open(path, "w") as f:
        f.write(HEADER + 'Shape "trianglemesh" "point3 P" [\n')
        for k in range(0, len(points), 1000):
            f.write(" ".join("%.6f %.6f %.6f" % p for p in points[k:k + 1000]) + "\n")
        f.write('] "integer indices" [\n')
        for k in range(0, len(tris), 1000):
            f.write(" ".join("%d %d %d" % t for t in tris[k:k + 1000]) + "\n")
        f.write("]\n")


def write_ply(path, points, tris):
    ply = path[:-len(".pbrt")] + ".ply"
    with open(ply, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (len(points), len(tris))).encode())
        f.write(b"".join(struct.pack("<3f", *p) for p in points))
        f.write(b"".join(struct.pack("<B3i", 3, *t) for t in tris))
    with open(path, "w") as f:
        f.write(HEADER + 'Shape "plymesh" "string filename" "%s"\n' % os.path.basename(ply))
    return ply


def mb(text):
    value, unit = text.split()
    return float(value) * (1024 if unit == "GB" else 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=1000, help="vertices per side (default 1000: 2M triangles)")
    ap.add_argument("--binary", default="build/tessera")
    a = ap.parse_args()
    points, tris = grid(a.grid)
    arrays_mb = (len(points) * 12 + len(tris) * 12) / 2**20
    with tempfile.TemporaryDirectory() as d:
        text, ply = os.path.join(d, "text.pbrt"), os.path.join(d, "ply.pbrt")
        write_text(text, points, tris)
        ply_file = write_ply(ply, points, tris)
        print("%d triangles, %d vertices: positions and indices take %.0f MB" % (len(tris), len(points), arrays_mb))
        for name, scene, data in (("text trianglemesh", text, text), ("binary PLY", ply, ply_file)):
            t0 = time.time()
            r = subprocess.run([a.binary, "info", scene], capture_output=True, text=True)
            secs = time.time() - t0
            if r.returncode != 0:
                sys.exit(r.stderr[-2000:])
            m = re.search(r"reading peaked at ([\d.]+ [MG]B), the built scene holds ([\d.]+ [MG]B)", r.stdout)
            if not m:
                sys.exit("bench_mesh_load: no memory line in `tessera info` output (not Linux?)")
            read, built = mb(m.group(1)), mb(m.group(2))
            print("%-18s file %5.1f MB: reading peaked at %4.0f MB (%.2fx the arrays), built scene %4.0f MB, %.2f s"
                  % (name, os.path.getsize(data) / 2**20, read, read / arrays_mb, built, secs))


if __name__ == "__main__":
    main()
