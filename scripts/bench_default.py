#!/usr/bin/env python3
"""Does the default pay? `--guide auto` against `--guide none` and `--guide qtable`
at equal time (not a test).

Every scene renders with each method for the same --time (learning and the
trial included), --threads 2 by default, and is compared with a reference:
an unguided render of --ref-time seconds with its own seed, made once and
cached in out/bench-default/refs/ (delete it after a change that alters
pictures). The error is relMSE against the reference minus the reference's
own noise (the relMSE its variance layer predicts: independent errors add),
i.e. the error against the converged image. Where that noise estimate is not
well below every method's error (fireflies in the reference inflate it), the
scene is judged on the raw relMSE (marked r).

Scenes: the shipped ones (scenes/*.pbrt, at their own resolution) and every
scene of ../shared/public-scenes at the resolution refs/log.json gives,
plus any --extra pbrt files. Per scene it prints the errors, default / best
of (none, qtable), default / none, and what the default's trial decided
(from its --stats: each window's guided / unguided figures, the outcome, the
samples it took out of the image), and checks the acceptance of issue 49:
default <= 1.05 x the better of none and qtable on every scene, and default
<= 0.6 x none wherever qtable <= 0.5 x none.

    nice -n 10 scripts/bench_default.py --times 20
    nice -n 10 scripts/bench_default.py --times 60 --scenes door-ajar pillars
    scripts/bench_default.py --furnace    # the closed white furnace at 128 spp

Each render's figures are cached in out/bench-default/runs/ (keyed by
scene, method, time, seed and the binary's size and time), so an
interrupted run goes on where it stopped; --fresh METHOD... renders those
methods again. Results: out/bench-default/results-<time>s.json.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PUBLIC = os.path.join(os.path.dirname(ROOT), "shared", "public-scenes")
REF_SEED = 987654321  # differs from every seed the renders use


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return r.stdout, r.stderr


def scene_list(a):
    """(name, path, --res args) of every scene to run."""
    scenes = []
    for path in sorted(os.listdir(os.path.join(ROOT, "scenes"))):
        if path.endswith(".pbrt"):
            scenes.append((path[:-5], os.path.join(ROOT, "scenes", path), []))
    log = os.path.join(a.public, "refs", "log.json")
    if os.path.exists(log):
        with open(log) as f:
            shipped = {s[0] for s in scenes}
            for key, v in json.load(f).items():
                name = os.path.splitext(v["file"])[0]
                name = "public-" + name if name in shipped else name  # cornell-box is both
                scenes.append((name, os.path.join(a.public, v["scene"]), ["--res", v["res"]]))
    for path in a.extra:
        scenes.append((os.path.splitext(os.path.basename(path))[0], os.path.abspath(path), []))
    if a.scenes:
        scenes = [s for s in scenes if s[0] in a.scenes]
    return scenes


def reference(a, name, path, res):
    exr = os.path.join(a.out, "refs", f"{name}-{a.ref_guide}-{int(a.ref_time)}s.exr")
    meta = exr[:-4] + ".json"
    if not os.path.exists(meta):
        os.makedirs(os.path.dirname(exr), exist_ok=True)
        cmd = [a.tessera, "render", path, "-q", "--no-preview", "--guide", a.ref_guide, "--time", str(a.ref_time),
               "--seed", str(REF_SEED), "--threads", str(a.threads), "-o", exr, "--stats", exr[:-4] + ".stats.json", *res]
        print(f"[{name}] reference: {a.ref_guide}, {a.ref_time:.0f} s ...", flush=True)
        run(cmd)
        with open(exr[:-4] + ".stats.json") as f:
            s = json.load(f)
        with open(meta, "w") as f:
            json.dump({"command": " ".join(cmd), "spp": s["spp"], "seconds": s["seconds"],
                       "estimated_relmse": s["estimated_relmse"]}, f, indent=1)
    return exr


def trial_summary(s):
    """What --guide auto's trial decided, from its stats."""
    if s.get("guide_trial") in (None, "none"):
        return {"decision": s.get("guide", "none") if s.get("guide") else "no guide"}
    windows = [{"spp": w["start_spp"], "ratio": w["guided_inefficiency"] / max(w["unguided_inefficiency"], 1e-300)}
               for w in s.get("guide_trial_windows", [])]
    return {"decision": s["guide_trial"], "windows": windows, "dropped": s.get("guide_trial_dropped", "none"),
            "dropped_spp": s.get("guide_trial_dropped_spp", 0)}


def render(a, name, path, res, method, seconds, seed, ref):
    stamp = os.stat(a.tessera)
    key = f"{name}-{method}-{seconds:g}s-seed{seed}"
    cache = os.path.join(a.out, "runs", key + ".json")
    binary = f"{stamp.st_size}-{int(stamp.st_mtime)}"
    stale = method in a.fresh and (a.fresh_since <= 0 or not os.path.exists(cache) or os.stat(cache).st_mtime < a.fresh_since)
    if os.path.exists(cache) and not stale:
        with open(cache) as f:
            row = json.load(f)
        if row.get("binary") == binary or method == "none" or not a.fresh_on_new_binary:
            return row
    os.makedirs(os.path.join(a.out, "runs"), exist_ok=True)
    img = os.path.join(a.out, "runs", key + ".exr")
    st = os.path.join(a.out, "runs", key + ".stats.json")
    _, err = run([a.tessera, "render", path, "-q", "--no-preview", "--guide", method, "--time", str(seconds),
                  "--seed", str(seed), "--threads", str(a.threads), "-o", img, "--stats", st, *res])
    with open(st) as f:
        s = json.load(f)
    c = json.loads(run([a.tessera, "compare", img, ref, "--json"])[0])
    row = {"relmse": c["relmse"], "relmse_vs_truth": c["relmse"] - c["reference_estimated_relmse"],
           "reference_noise": c["reference_estimated_relmse"], "spp": s["spp"], "seconds": s["seconds"],
           "trial": trial_summary(s), "log": [l for l in err.splitlines() if "guide trial" in l], "binary": binary}
    with open(cache, "w") as f:
        json.dump(row, f, indent=1)
    return row


# A closed white furnace: an albedo-1 diffuse box, one small black area light
# inside, depth 1000 (paths run about 70 bounces); issue 49's second case.
FURNACE = """LookAt 0 0 -0.9  0 0 1  0 1 0
Camera "perspective" "float fov" [ 70 ]
Film "rgb" "integer xresolution" [ 64 ] "integer yresolution" [ 64 ]
Sampler "independent" "integer pixelsamples" [ 128 ]
Integrator "path" "integer maxdepth" [ 1000 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 1 1 1 ]
Shape "trianglemesh" "point3 P" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1 ]
  "integer indices" [ 0 2 3 0 1 2  4 7 6 4 6 5  0 3 7 0 7 4  1 5 6 1 6 2  0 4 5 0 5 1  3 2 6 3 6 7 ]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
Shape "trianglemesh" "point3 P" [ -0.3 0.999 0.2  0.3 0.999 0.2  0.3 0.999 0.8  -0.3 0.999 0.8 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
"""


def furnace(a):
    """The default against --guide none at equal spp (128) in the closed furnace: relMSE against
    an unguided 1024-spp reference minus its noise; the acceptance is <= 1.2x."""
    d = os.path.join(a.out, "furnace")
    os.makedirs(d, exist_ok=True)
    scene = os.path.join(d, "furnace-box.pbrt")
    with open(scene, "w") as f:
        f.write(FURNACE)
    ref = os.path.join(d, "reference.exr")
    if not os.path.exists(ref):
        print("[furnace-box] reference: none, 1024 spp ...", flush=True)
        run([a.tessera, "render", scene, "-q", "--no-preview", "--guide", "none", "--spp", "1024", "--seed", str(REF_SEED),
             "--threads", str(a.threads), "-o", ref])
    out = {}
    for method in ("auto", "none"):
        img = os.path.join(d, f"{method}.exr")
        _, err = run([a.tessera, "render", scene, "-q", "--no-preview", "--guide", method, "--spp", "128", "--seed", "1",
                      "--threads", str(a.threads), "-o", img, "--stats", img[:-4] + ".json"])
        c = json.loads(run([a.tessera, "compare", img, ref, "--json"])[0])
        out[method] = c["relmse"] - c["reference_estimated_relmse"]
        for line in err.splitlines():
            if "guide trial" in line:
                print(f"[furnace-box] {line}")
    print(f"[furnace-box] 128 spp, relMSE minus reference noise: auto {out['auto']:.4g}, none {out['none']:.4g}, "
          f"auto/none {out['auto'] / max(out['none'], 1e-30):.2f} (acceptance <= 1.2)", flush=True)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=os.path.join(ROOT, "build", "tessera"))
    ap.add_argument("--public", default=PUBLIC, help="the public scenes (refs/log.json gives each --res)")
    ap.add_argument("--scenes", nargs="*", default=[], help="only these (names as printed)")
    ap.add_argument("--extra", nargs="*", default=[], help="more pbrt files, at their own resolution")
    ap.add_argument("--methods", nargs="*", default=["auto", "none", "qtable"])
    ap.add_argument("--times", nargs="*", type=float, default=[20.0])
    ap.add_argument("--seeds", nargs="*", type=int, default=[1])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ref-time", type=float, default=60.0, help="seconds of each reference")
    ap.add_argument("--ref-guide", default="none", help="what renders the references")
    ap.add_argument("--fresh", nargs="*", default=[], help="render these methods again even when cached")
    ap.add_argument("--fresh-since", type=float, default=0.0,
                    help="with --fresh: only renders cached before this time (seconds since the epoch) are rendered again")
    ap.add_argument("--fresh-on-new-binary", action="store_true",
                    help="render guided methods again when the binary changed since they were cached")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-default"))
    ap.add_argument("--furnace", action="store_true", help="only the closed white furnace at 128 spp (auto against none)")
    a = ap.parse_args()
    if a.furnace:
        furnace(a)
        return
    scenes = scene_list(a)
    if not scenes:
        sys.exit("bench_default.py: no scene matches --scenes (names as printed: door-ajar, cornell-box-silver, ...)")
    os.makedirs(a.out, exist_ok=True)
    for seconds in a.times:
        results = {"time_s": seconds, "threads": a.threads, "ref_time_s": a.ref_time, "seeds": a.seeds, "scenes": {}}
        for name, path, res in scenes:
            ref = reference(a, name, path, res)
            entry = {}
            for method in a.methods:
                rows = [render(a, name, path, res, method, seconds, seed, ref) for seed in a.seeds]
                entry[method] = {"relmse": statistics.median(r["relmse_vs_truth"] for r in rows),
                                 "spp": statistics.median(r["spp"] for r in rows), "runs": rows}
                t = rows[0]["trial"]
                print(f"[{name}] {method:6s} relMSE {entry[method]['relmse']:.4g} (raw {rows[0]['relmse']:.4g}, "
                      f"reference noise {rows[0]['reference_noise']:.3g})  spp {entry[method]['spp']:.0f}"
                      + (f"  trial {t}" if method == "auto" else ""), flush=True)
            results["scenes"][name] = entry
        report(results, a)
        with open(os.path.join(a.out, f"results-{seconds:g}s.json"), "w") as f:
            json.dump(results, f, indent=1)
        print(f"wrote {os.path.join(a.out, f'results-{seconds:g}s.json')}\n")


def report(results, a):
    print(f"\n{results['time_s']:g} s per render, {results['threads']} threads, seeds {results['seeds']}; relMSE against "
          f"a {results['ref_time_s']:g} s {a.ref_guide} reference minus its own noise")
    print("(r: judged on the raw relMSE, where the reference's own noise estimate is not well below the errors)")
    print(f"{'scene':34s} {'auto':>9s} {'none':>9s} {'qtable':>9s} {'auto/best':>9s} {'auto/none':>9s}  decision [window spp:ratio]")
    fails = []
    for name, e in results["scenes"].items():
        if not all(m in e for m in ("auto", "none", "qtable")):
            continue
        auto, none, qt = e["auto"]["relmse"], e["none"]["relmse"], e["qtable"]["relmse"]
        # Where the reference's noise estimate is not well below every error (fireflies
        # inflate it; the difference may even be negative), compare the raw errors.
        raw = {m: statistics.median(r["relmse"] for r in e[m]["runs"]) for m in ("auto", "none", "qtable")}
        noise = e["none"]["runs"][0]["reference_noise"]
        e["judged_on"] = "raw" if noise > 0.5 * min(raw.values()) else "minus reference noise"
        if e["judged_on"] == "raw":
            auto, none, qt = raw["auto"], raw["none"], raw["qtable"]
        best = max(min(none, qt), 1e-30)
        r_best, r_none, q_none = auto / best, auto / max(none, 1e-30), qt / max(none, 1e-30)
        e["auto_over_best"], e["auto_over_none"], e["qtable_over_none"] = r_best, r_none, q_none
        e["judged"] = {"auto": auto, "none": none, "qtable": qt}
        ok = r_best <= 1.05 and (q_none > 0.5 or r_none <= 0.6)
        if not ok:
            fails.append(name)
        t = e["auto"]["runs"][0]["trial"]
        windows = " ".join(f"{w['spp']}:{w['ratio']:.2g}" for w in t.get("windows", []))
        dropped = f", dropped {t['dropped']} {t['dropped_spp']} spp" if t.get("dropped", "none") != "none" else ""
        print(f"{name:34s} {auto:9.4g} {none:9.4g} {qt:9.4g} {r_best:9.2f} {r_none:9.2f}{'r' if e['judged_on'] == 'raw' else ' '} "
              f"{t['decision']} "
              f"[{windows}]{dropped}{'' if ok else '  MISSED'}")
    results["missed"] = fails
    print(f"acceptance (auto <= 1.05 x best; auto <= 0.6 x none where qtable <= 0.5 x none): "
          f"{'met on every scene' if not fails else 'missed on ' + ', '.join(fails)}")


if __name__ == "__main__":
    main()
