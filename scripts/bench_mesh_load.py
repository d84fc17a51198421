#!/usr/bin/env python3
"""Peak memory and time of loading a big text trianglemesh.

Writes an N x N vertex grid (2 (N-1)^2 triangles) as one pbrt-v4
`trianglemesh` and runs `tessera info` on it under /usr/bin/time -v, which
reports the peak resident set size. Prints the file size, triangles, peak
MB, bytes per triangle and seconds.

    python3 scripts/bench_mesh_load.py [--grid 1000] [--binary build/tessera]
"""
import argparse
import os
import random
import re
import subprocess
import sys
import tempfile


def write_grid(path, n):
    rnd = random.Random(1)
    with open(path, "w") as f:
        f.write('LookAt 0 5 -5 0 0 0 0 1 0\nCamera "perspective"\nWorldBegin\n'
                'LightSource "point" "point3 from" [0 3 0] "rgb I" [10 10 10]\n'
                'Shape "trianglemesh" "point3 P" [\n')
        for j in range(n):
            f.write(" ".join("%.6f %.6f %.6f" % (i / n * 4 - 2, rnd.random() * 0.01, j / n * 4 - 2)
                             for i in range(n)) + "\n")
        f.write('] "integer indices" [\n')
        for j in range(n - 1):
            row = []
            for i in range(n - 1):
                a = j * n + i
                row.append("%d %d %d %d %d %d" % (a, a + 1, a + n + 1, a, a + n + 1, a + n))
            f.write(" ".join(row) + "\n")
        f.write("]\n")
    return 2 * (n - 1) ** 2


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=1000, help="vertices per side (default 1000: 2M triangles)")
    ap.add_argument("--binary", default="build/tessera")
    a = ap.parse_args()
    if not os.path.exists("/usr/bin/time"):
        sys.exit("bench_mesh_load: needs /usr/bin/time (Debian package 'time')")
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "grid.pbrt")
        tris = write_grid(scene, a.grid)
        r = subprocess.run(["/usr/bin/time", "-v", a.binary, "info", scene], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(r.stderr[-2000:])
        peak_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1))
        wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", r.stderr).group(1)
        secs = sum(float(x) * 60 ** k for k, x in enumerate(reversed(wall.split(":"))))
        size_mb = os.path.getsize(scene) / 1e6
    print("file %.1f MB, %d triangles: peak %.0f MB (%.0f bytes a triangle), %.2f s"
          % (size_mb, tris, peak_kb / 1024, peak_kb * 1024 / tris, secs))


if __name__ == "__main__":
    main()
