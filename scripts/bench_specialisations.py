#!/usr/bin/env python3
"""What the effects-set specialisations buy (a benchmark, not a test): each
scene's samples/s with the integrator specialised on its effects (the
default) against the full integrator (--full-specialisation), per guide,
interleaved, medians of --repeats.

  scripts/bench_specialisations.py [--scenes A.pbrt ...] [--guides none qtable neural]

Default scenes: the shipped ones and the public scenes under
../shared/public-scenes that load within a few seconds at the bench's
resolution. Prints scene, guide, the specialisation the scene ran
(tessera's stats: "specialisation"), both rates and their ratio; and which
specialisations the scenes did exercise, so that one no scene pays for can
be named (docs/backends.md, Specialisations).
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent


def render(tessera, scene, guide, full, args, tmp):
    stats = pathlib.Path(tmp) / "stats.json"
    cmd = [tessera, "render", str(scene), "-o", str(pathlib.Path(tmp) / "x.exr"), "--no-preview", "-q",
           "--stats", str(stats), "--guide", guide, "--backend", "embree", "--spp", str(args.spp),
           "--res", args.res, "--seed", "1", "--threads", str(args.threads)]
    if full:
        cmd.append("--full-specialisation")
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=600)
    if r.returncode != 0:
        raise RuntimeError((r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1])
    j = json.loads(stats.read_text())
    return j["samples_per_second"], j.get("specialisation", "?")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tessera", default=str(ROOT / "build" / "tessera"))
    p.add_argument("--scenes", nargs="*")
    p.add_argument("--guides", nargs="*", default=["none", "qtable", "neural"])
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--res", default="160x120")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    scenes = [pathlib.Path(s) for s in args.scenes] if args.scenes else sorted((ROOT / "scenes").glob("*.pbrt"))
    used = {}
    print(f"{'scene':28s} {'guide':7s} {'specialisation':52s} {'spec Ms/s':>9s} {'full Ms/s':>9s} {'gain':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            for guide in args.guides:
                spec_rates, full_rates, spec = [], [], "?"
                try:
                    for _ in range(args.repeats):
                        rate, spec = render(args.tessera, scene, guide, False, args, tmp)
                        spec_rates.append(rate)
                        full_rates.append(render(args.tessera, scene, guide, True, args, tmp)[0])
                except (RuntimeError, subprocess.TimeoutExpired) as e:
                    print(f"{scene.stem:28s} {guide:7s} skipped: {e}")
                    continue
                gain = statistics.median(spec_rates) / statistics.median(full_rates)
                used.setdefault(spec, []).append(gain)
                print(f"{scene.stem[:28]:28s} {guide:7s} {spec[:52]:52s} {statistics.median(spec_rates) / 1e6:9.3f} "
                      f"{statistics.median(full_rates) / 1e6:9.3f} {gain:6.3f}", flush=True)
    print("\nspecialisations exercised (best gain over the full integrator):")
    for spec, gains in sorted(used.items(), key=lambda kv: -max(kv[1])):
        print(f"  {spec:60s} {max(gains):6.3f} ({len(gains)} cases)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
