#!/usr/bin/env python3
"""Render public pbrt-v4 scenes with Tessera and compare them with pbrt-v4's own renders.

    scripts/conformance.py --corpus /work/shared/public-scenes --spp 16 --json conf.json
    scripts/conformance.py SCENE.pbrt ... [--refs DIR]

For every scene: the warnings `tessera info` prints (the features Tessera
approximates or ignores), whether `tessera render` finished (ok, error,
crash, timeout) and in how many seconds, and, where a reference EXR exists,
how far Tessera's image is from it: the ratio of the channel means (a
feature missing or too bright shows here first), the worst 8x8 block of
`tessera compare --block 8` (the ratio of block mean luminances farthest
from 1, and where) and the share of blocks off by more than 10 %. Block
means wash out the Monte Carlo noise of both images, so what they show is
mostly bias; at low spp, small and dark blocks still carry noise.

Scenes come from the command line or from --corpus DIR: every scene that
DIR/refs/log.json lists ({"key": {"scene": relative path, "res": "WxH",
"file": reference EXR name}}), else every *.pbrt under DIR. A scene with a
reference is rendered at the reference's resolution (log.json's "res",
else the EXR's data window) so that the two compare. References are matched
by log.json, else by name: REFS/<scene stem>.exr.

Prints a markdown table and each scene's warnings; --json writes everything.
Exit status 0 when it ran (whatever the scenes did), 2 on bad arguments.
Standard library only.
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WARNING_PREFIX = "tessera: warning: "
ERROR_PREFIX = "tessera: error: "
BLOCK = 8


def exr_resolution(path):
    """(width, height) from an OpenEXR header's dataWindow, or None."""
    try:
        with open(path, "rb") as f:
            data = f.read(1 << 16)  # headers are small; attributes come before the offset table
    except OSError:
        return None
    if len(data) < 8 or struct.unpack("<I", data[:4])[0] != 20000630:
        return None
    pos = 8
    while pos < len(data):
        end = data.find(b"\0", pos)
        if end <= pos:  # empty name: end of header
            return None
        name = data[pos:end]
        tend = data.find(b"\0", end + 1)
        if tend < 0 or tend + 5 > len(data):
            return None
        size = struct.unpack("<i", data[tend + 1:tend + 5])[0]
        value = data[tend + 5:tend + 5 + size]
        if name == b"dataWindow" and size == 16:
            xmin, ymin, xmax, ymax = struct.unpack("<4i", value)
            return xmax - xmin + 1, ymax - ymin + 1
        pos = tend + 5 + size
    return None


def parse_res(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except (AttributeError, ValueError):
        return None
    return (w, h) if w > 0 and h > 0 else None


def load_log(refs):
    """REFS/log.json ({key: {"scene", "res", "file", ...}}), or {} when absent."""
    path = os.path.join(refs, "log.json") if refs else None
    if not path or not os.path.isfile(path):
        return {}
    with open(path) as f:
        log = json.load(f)
    if not isinstance(log, dict):
        raise ValueError(f"{path}: not a JSON object")
    return {k: e for k, e in log.items() if isinstance(e, dict) and isinstance(e.get("scene"), str)}


def collect_scenes(args):
    """[{name, scene, ref, res}] in the order given (or the log's order)."""
    corpus = os.path.abspath(args.corpus) if args.corpus else None
    refs = args.refs or (os.path.join(corpus, "refs") if corpus else None)
    refs = os.path.abspath(refs) if refs else None
    log = load_log(refs)
    # log.json's scene paths are relative to the corpus: the folder above refs/ unless --corpus says otherwise.
    log_root = corpus or (os.path.dirname(refs) if refs else None)
    by_path = {os.path.realpath(os.path.join(log_root, e["scene"])): (k, e) for k, e in log.items()}

    paths = [os.path.abspath(s) for s in args.scenes]
    if corpus:
        if log:
            paths += [os.path.join(log_root, e["scene"]) for e in log.values()]
        else:
            found = []
            for dirpath, _, files in os.walk(corpus):
                found += [os.path.join(dirpath, f) for f in files if f.endswith(".pbrt")]
            paths += sorted(found)

    scenes, names = [], set()
    for path in paths:
        key, entry = by_path.get(os.path.realpath(path), (None, {}))
        ref = os.path.join(refs, entry["file"]) if entry.get("file") and refs else None
        if ref is None and refs:
            guess = os.path.join(refs, os.path.splitext(os.path.basename(path))[0] + ".exr")
            ref = guess if os.path.isfile(guess) else None
        if ref and not os.path.isfile(ref):
            ref = None
        res = parse_res(entry.get("res")) or (exr_resolution(ref) if ref else None)
        label = key or (os.path.relpath(path, corpus)[:-5] if corpus and path.startswith(corpus + os.sep) else path)
        name = os.path.splitext(os.path.basename(ref or path))[0]
        base, n = name, 2
        while name in names:
            name, n = f"{base}-{n}", n + 1
        names.add(name)
        scenes.append({"label": label, "name": name, "scene": path, "ref": ref,
                       "res": f"{res[0]}x{res[1]}" if res else None})
    return scenes, corpus or log_root


def run(cmd, timeout):
    """(status, returncode, seconds, stdout, stderr)."""
    start = time.monotonic()
    try:
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, errors="replace",
                           timeout=timeout)
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        err = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
        return "timeout", None, time.monotonic() - start, out, err
    seconds = time.monotonic() - start
    status = "ok" if r.returncode == 0 else ("crash" if r.returncode < 0 else "error")
    return status, r.returncode, seconds, r.stdout, r.stderr


def first_error(stderr, returncode):
    lines = [l.strip() for l in stderr.splitlines() if l.strip()]
    for l in lines:
        if l.startswith(ERROR_PREFIX):
            return l[len(ERROR_PREFIX):]
    for l in lines:
        if not l.startswith(WARNING_PREFIX):
            return l
    return f"exit status {returncode}"


def warnings_of(stderr, corpus):
    """Deduplicated warning lines, in order, with file:line: kept (relative to the corpus where inside it)."""
    seen, out = set(), []
    for line in stderr.splitlines():
        if not line.startswith(WARNING_PREFIX):
            continue
        w = line[len(WARNING_PREFIX):].strip()
        if corpus and w.startswith(corpus + os.sep):
            w = w[len(corpus) + 1:]
        if w not in seen:
            seen.add(w)
            out.append(w)
    return out


def conform(s, args, corpus):
    binary = args.binary
    info = run([binary, "info", s["scene"]], args.timeout)
    s["warnings"] = warnings_of(info[4], corpus)
    if info[0] != "ok":
        s["info_status"] = info[0]

    exr = os.path.join(args.out, s["name"] + ".exr")
    stats = os.path.join(args.out, s["name"] + ".json")
    for stale in (exr, stats):
        if os.path.exists(stale):
            os.remove(stale)
    cmd = [binary, "render", s["scene"], "--spp", str(args.spp), "-o", exr, "--stats", stats, "--no-preview", "-q"]
    if s["res"]:
        cmd += ["--res", s["res"]]
    if args.threads is not None:
        cmd += ["--threads", str(args.threads)]
    cmd += args.render_arg
    s["command"] = cmd
    status, rc, seconds, _, err = run(cmd, args.timeout)
    s.update(status=status, returncode=rc, seconds=round(seconds, 2))
    if status == "error":
        s["error"] = first_error(err, rc)
    elif status == "crash":
        s["error"] = f"killed by signal {-rc}"
    if os.path.isfile(stats):
        try:
            with open(stats) as f:
                s["stats"] = json.load(f)
        except (OSError, ValueError):
            pass
    if status != "ok" or not s["ref"]:
        return s

    cstatus, crc, _, out, cerr = run([binary, "compare", exr, s["ref"], "--json", "--block", str(BLOCK)], args.timeout)
    if cstatus != "ok":
        s["compare_error"] = first_error(cerr, crc)
        return s
    try:
        c = json.loads(out)
    except ValueError:
        s["compare_error"] = "unreadable compare output: " + out.strip()[:200]
        return s
    s["compare"] = c
    s["rgb_ratio"] = [m / r if r else None for m, r in zip(c["mean_rgb"], c["reference_mean_rgb"])]
    s["worst_block_ratio"] = c.get("worst_block_ratio")
    s["worst_block"] = [c.get("worst_block_x"), c.get("worst_block_y")]
    s["blocks_off_fraction"] = c.get("blocks_off_fraction")
    return s


def fmt(v, spec=".2f"):
    return "–" if v is None else format(v, spec)


def table(scenes):
    rows = [f"| scene | status | transport | seconds | R G B ratio | worst {BLOCK}x{BLOCK} block | blocks off >10% | warnings |",
            "|---|---|---|---:|---|---|---:|---:|"]
    for s in scenes:
        status = s.get("status", "?")
        if s.get("error"):
            status += ": " + s["error"].replace("|", "\\|")
        ratio = " ".join(fmt(v) for v in s["rgb_ratio"]) if "rgb_ratio" in s else ("no ref" if not s["ref"] else "–")
        if s.get("compare_error"):
            ratio = "compare failed: " + s["compare_error"].replace("|", "\\|")
        worst = "–"
        if s.get("worst_block_ratio") is not None:
            worst = f"{s['worst_block_ratio']:.2f} @({s['worst_block'][0]},{s['worst_block'][1]})"
        off = fmt(100 * s["blocks_off_fraction"], ".0f") + " %" if s.get("blocks_off_fraction") is not None else "–"
        transport = (s.get("stats") or {}).get("transport", "–")  # rgb or spectral (--spectral auto decides)
        rows.append(f"| {s['label']} | {status} | {transport} | {fmt(s.get('seconds'), '.1f')} | {ratio} | {worst} | {off} | "
                    f"{len(s.get('warnings', []))} |")
    return "\n".join(rows)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="*", metavar="SCENE.pbrt")
    p.add_argument("--corpus", help="every scene of DIR/refs/log.json, else every *.pbrt under DIR")
    p.add_argument("--refs", help="folder of reference EXRs (default: CORPUS/refs)")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--threads", type=int, help="render threads (default: Tessera's, all cores)")
    p.add_argument("--timeout", type=float, default=600, help="seconds per command (default 600)")
    p.add_argument("--out", default=os.path.join("out", "conformance"), help="renders and stats (default out/conformance)")
    p.add_argument("--json", help="write every result here")
    p.add_argument("--binary", default=os.path.join(ROOT, "build", "tessera"))
    p.add_argument("--render-arg", action="append", default=[], metavar="ARG",
                   help="extra argument for every render (repeat: --render-arg=--spectral --render-arg=on)")
    args = p.parse_args()
    if not args.scenes and not args.corpus:
        p.error("give scene files or --corpus DIR")
    if args.corpus and not os.path.isdir(args.corpus):
        p.error(f"--corpus {args.corpus}: not a folder")
    if args.refs and not os.path.isdir(args.refs):
        p.error(f"--refs {args.refs}: not a folder")
    if args.spp < 1 or args.timeout <= 0 or (args.threads is not None and args.threads < 0):
        p.error("--spp must be >= 1, --timeout > 0, --threads >= 0")
    missing = [s for s in args.scenes if not os.path.isfile(s)]
    if missing:
        p.error("no such scene file: " + ", ".join(missing))
    if not (os.path.isfile(args.binary) and os.access(args.binary, os.X_OK)):
        p.error(f"--binary {args.binary}: not an executable (build with cmake --build build)")
    try:
        scenes, corpus = collect_scenes(args)
    except (OSError, ValueError) as e:
        p.error(f"reading the references' log.json: {e}")
    if not scenes:
        p.error("no scenes found")
    os.makedirs(args.out, exist_ok=True)

    for i, s in enumerate(scenes):
        print(f"[{i + 1}/{len(scenes)}] {s['label']}", file=sys.stderr, flush=True)
        conform(s, args, corpus)
        print(f"    {s['status']} in {s['seconds']:.1f} s" + (f": {s['error']}" if s.get("error") else ""),
              file=sys.stderr, flush=True)

    print(table(scenes))
    print()
    for s in scenes:
        if s["warnings"]:
            print(f"**{s['label']}**")
            for w in s["warnings"]:
                print(f"- {w}")
            print()
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"spp": args.spp, "threads": args.threads, "timeout": args.timeout, "block": BLOCK,
                       "binary": os.path.abspath(args.binary), "corpus": corpus, "scenes": scenes}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
