#!/usr/bin/env python3
"""Samples/s of two tessera binaries on the shipped scenes, interleaved (a
benchmark, not a test): for a change that must not cost speed, build the
commit before it beside this one and compare.

  scripts/bench_ab.py --a OLD/build/tessera --b build/tessera [--repeats 3]

Each scene x guide is rendered at a fixed spp by A then B, --repeats times
(interleaved, so that a machine's drift hits both alike); the figure is the
median of the renders' samples/s (their stats JSON: render time only, not
loading). Prints one line per case with B/A and the geometric mean of B/A.
"""
import argparse
import json
import math
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent


def samples_per_s(tessera, scene, guide, args, tmp):
    stats = pathlib.Path(tmp) / "stats.json"
    cmd = [tessera, "render", str(scene), "-o", str(pathlib.Path(tmp) / "x.exr"), "--no-preview", "-q",
           "--stats", str(stats), "--guide", guide, "--backend", args.backend, "--spp", str(args.spp),
           "--res", args.res, "--seed", "1", "--threads", str(args.threads)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return json.loads(stats.read_text())["samples_per_second"]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a", required=True, help="the binary before")
    p.add_argument("--b", required=True, help="the binary after")
    p.add_argument("--scenes", nargs="*", help="default: scenes/*.pbrt")
    p.add_argument("--guides", nargs="*", default=["none", "qtable", "neural"])
    p.add_argument("--backend", default="embree")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--res", default="160x120")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    scenes = [pathlib.Path(s) for s in args.scenes] if args.scenes else sorted((ROOT / "scenes").glob("*.pbrt"))
    ratios = []
    print(f"{'scene':12s} {'guide':7s} {'A Msamples/s':>13s} {'B Msamples/s':>13s} {'B/A':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            for guide in args.guides:
                a, b = [], []
                for _ in range(args.repeats):
                    a.append(samples_per_s(args.a, scene, guide, args, tmp))
                    b.append(samples_per_s(args.b, scene, guide, args, tmp))
                ma, mb = statistics.median(a), statistics.median(b)
                ratios.append(mb / ma)
                print(f"{scene.stem:12s} {guide:7s} {ma / 1e6:13.3f} {mb / 1e6:13.3f} {mb / ma:6.3f}", flush=True)
    gm = math.exp(sum(math.log(r) for r in ratios) / len(ratios))
    print(f"geometric mean of B/A over {len(ratios)} cases: {gm:.3f} (medians of {args.repeats})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
