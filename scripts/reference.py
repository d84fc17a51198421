#!/usr/bin/env python3
"""High-sample reference images, rendered once and cached.

A reference is plain path tracing (--guide none, NEE+MIS) at many samples per
pixel with its own seed, so error curves of any method, guided ones included,
are measured against something that does not depend on the method judged.

    scripts/reference.py scenes/door-ajar.pbrt [--spp 8192]

prints the cached EXR's path, rendering it first if needed. Beside each
reference, <name>.json records the exact command, how long it took, the
threads, the scene file's SHA-256 and the relMSE its own variance layer
predicts (its noise floor: measured errors against it include about that
much). The cache key is (scene file contents, spp, seed, extra arguments):
editing the scene file renders a new reference; a changed renderer does not
(delete the cache, or pass --force, after a change that alters pictures).
Other scripts import reference() from here.
"""
import argparse
import datetime
import hashlib
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_CACHE = os.path.join(ROOT, "out", "references")
DEFAULT_SPP = 8192
DEFAULT_SEED = 987654321  # differs from every seed the benchmarks render with
DEFAULT_TESSERA = os.path.join(ROOT, "build", "tessera")


def _run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def _git_commit():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True).stdout.strip()
    except OSError:
        return ""


# Part of every cache key: raise it when Tessera's converged picture of a
# scene changes (2: spectral transport chosen by --spectral auto, the
# consistent layered BSDF), so that no stale reference is reused.
PICTURE_REVISION = 2


def cache_paths(scene, spp=DEFAULT_SPP, seed=DEFAULT_SEED, extra_args=(), cache=DEFAULT_CACHE):
    """(exr, json) where the reference of these settings lives."""
    with open(scene, "rb") as f:
        scene_hash = hashlib.sha256(f.read()).hexdigest()
    key = hashlib.sha256(f"{scene_hash} {spp} {seed} {' '.join(extra_args)} r{PICTURE_REVISION}".encode()).hexdigest()[:10]
    stem = os.path.splitext(os.path.basename(scene))[0]
    exr = os.path.join(cache, f"{stem}-{spp}spp-{key}.exr")
    return exr, exr[:-4] + ".json", scene_hash


def reference(scene, spp=DEFAULT_SPP, seed=DEFAULT_SEED, extra_args=(), cache=DEFAULT_CACHE, tessera=DEFAULT_TESSERA,
              threads=0, force=False, log=print):
    """Path of the reference EXR of `scene` and its metadata (dict), rendering it when not cached."""
    exr, meta_path, scene_hash = cache_paths(scene, spp, seed, extra_args, cache)
    if not force and os.path.exists(exr) and os.path.exists(meta_path):
        with open(meta_path) as f:
            return exr, json.load(f)
    os.makedirs(cache, exist_ok=True)
    stats = exr[:-4] + ".stats.json"
    cmd = [tessera, "render", scene, "-q", "--no-preview", "--guide", "none", "--spp", str(spp), "--seed", str(seed),
           "-o", exr, "--stats", stats, *(["--threads", str(threads)] if threads else []), *extra_args]
    log(f"reference: {os.path.basename(scene)}, {spp} spp unguided (cached in {os.path.relpath(cache, ROOT)}) ...")
    t0 = time.perf_counter()
    _run(cmd)
    seconds = time.perf_counter() - t0
    with open(stats) as f:
        s = json.load(f)
    meta = {"scene": os.path.relpath(scene, ROOT), "scene_sha256": scene_hash, "spp": spp, "seed": seed,
            "guide": "none", "command": " ".join(os.path.relpath(c, ROOT) if os.path.isabs(c) else c for c in cmd),
            "seconds": round(seconds, 2), "threads": s.get("threads"), "estimated_relmse": s.get("estimated_relmse"),
            "git_commit": _git_commit(), "date": datetime.datetime.now().isoformat(timespec="seconds")}
    with open(meta_path, "w") as f:
        json.dump(meta, f, indent=2)
    log(f"reference: {seconds:.0f} s, its own estimated relMSE {meta['estimated_relmse']:.3g}")
    return exr, meta


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="+", help="pbrt-v4 scene file(s)")
    ap.add_argument("--spp", type=int, default=DEFAULT_SPP)
    ap.add_argument("--seed", type=int, default=DEFAULT_SEED)
    ap.add_argument("--cache", default=DEFAULT_CACHE)
    ap.add_argument("--tessera", default=DEFAULT_TESSERA)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--force", action="store_true", help="render again even when cached")
    ap.add_argument("--render-args", default="", help="extra options for the render, e.g. '--res 128x96'")
    a = ap.parse_args()
    for scene in a.scene:
        exr, meta = reference(scene, a.spp, a.seed, a.render_args.split(), a.cache, a.tessera, a.threads, a.force,
                              log=lambda m: print(m, file=sys.stderr, flush=True))
        print(f"{exr}  ({meta['spp']} spp, {meta['seconds']} s on {meta['threads']} threads, "
              f"noise floor relMSE {meta['estimated_relmse']:.3g})")


if __name__ == "__main__":
    main()
