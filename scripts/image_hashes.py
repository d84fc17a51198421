#!/usr/bin/env python3
"""Pixel hashes of every shipped scene x guide x backend at a fixed seed.

A refactoring that must not change a pixel is checked in two steps: record
the hashes with the binary of the commit before the change, then compare
with the binary after it:

  scripts/image_hashes.py --tessera OLD/build/tessera --out /tmp/before.json
  scripts/image_hashes.py --tessera build/tessera --compare /tmp/before.json

The hash covers the EXR's pixel chunks only (mean and variance layers): its
header holds the render time, which differs from run to run. Exit status 1
when any image differs from the recorded one (each named on one line).
"""
import argparse
import hashlib
import json
import os
import pathlib
import struct
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
GUIDES = ["none", "qtable", "neural"]
BACKENDS = ["embree", "bvh", "emulated-device"]


def exr_pixel_hash(path):
    """SHA-256 of the bytes after the header and the chunk offset table."""
    data = pathlib.Path(path).read_bytes()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    pos = 8
    while data[pos] != 0:  # attributes: name\0 type\0 int32 size, value
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        pos = type_end + 5 + size
    # The offset table's first entry is where the first chunk starts; the
    # chunks (y, size, data) do not depend on the header's length.
    (first_chunk,) = struct.unpack_from("<Q", data, pos + 1)
    return hashlib.sha256(data[first_chunk:]).hexdigest()


def render(tessera, scene, guide, backend, out_dir, args):
    out = pathlib.Path(out_dir) / f"{scene.stem}-{guide}-{backend}.exr"
    cmd = [str(tessera), "render", str(scene), "-o", str(out), "--no-preview", "-q",
           "--guide", guide, "--backend", backend, "--seed", str(args.seed),
           "--spp", str(args.spp), "--res", args.res, "--threads", str(args.threads)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return None, (r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1]
    return exr_pixel_hash(out), None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tessera", default=str(ROOT / "build" / "tessera"), help="the binary to render with")
    p.add_argument("--out", help="write the hashes here (JSON)")
    p.add_argument("--compare", help="compare with hashes recorded earlier (JSON)")
    p.add_argument("--scenes", nargs="*", help="scene files (default: scenes/*.pbrt)")
    p.add_argument("--guides", nargs="*", default=GUIDES)
    p.add_argument("--backends", nargs="*", default=BACKENDS)
    p.add_argument("--spp", type=int, default=24)
    p.add_argument("--res", default="64x48")
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--threads", type=int, default=2)
    args = p.parse_args()
    if not args.out and not args.compare:
        p.error("give --out, --compare or both")
    scenes = [pathlib.Path(s) for s in args.scenes] if args.scenes else sorted((ROOT / "scenes").glob("*.pbrt"))
    recorded = json.loads(pathlib.Path(args.compare).read_text()) if args.compare else None
    if recorded:  # the settings the hashes were recorded with win
        for k in ("spp", "res", "seed"):
            setattr(args, k, recorded["settings"][k])
    hashes, differ, failed = {}, [], []
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            for guide in args.guides:
                for backend in args.backends:
                    key = f"{scene.stem} {guide} {backend}"
                    h, err = render(args.tessera, scene, guide, backend, tmp, args)
                    hashes[key] = h if h else "error: " + err
                    status = "ok"
                    if recorded is not None:
                        old = recorded["images"].get(key)
                        if old is None:
                            status = "new"
                        elif old != hashes[key]:
                            status = "DIFFERS"
                            differ.append(key)
                    if h is None:
                        failed.append(key)
                    print(f"{key:40s} {hashes[key][:16]:16s} {status}", flush=True)
    if args.out:
        settings = {"spp": args.spp, "res": args.res, "seed": args.seed}
        pathlib.Path(args.out).write_text(json.dumps({"settings": settings, "images": hashes}, indent=1) + "\n")
    if recorded is not None:
        print(f"{len(hashes) - len(differ)} of {len(hashes)} images identical to {args.compare}")
        for key in differ:
            print(f"differs: {key}")
    for key in failed:
        print(f"did not render: {key}: {hashes[key]}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
