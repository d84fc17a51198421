#!/usr/bin/env python3
"""Guiding benchmark (not a test): learned guiding versus plain path tracing
at equal wall-clock time, per shipped scene.

For each scene, every method renders with the same --time budget (training
included: the guide learns during the timed render), NEE+MIS on in all, and
is compared with a reference image:
  none       plain path tracing
  qtable     expected-SARSA Q-table guiding (Dahm & Keller), the default
  qlearning  the Q-learning "max" rule, for the comparison the paper makes
  qtable-throughput  qtable with pbrt-v4's throughput roulette alone (not run
             by default): what guided sampling costs per sample without the
             longer light-carrying paths of guided roulette
Reported per scene and method (median over --repeats seeds): relMSE against
the reference, the same minus the reference's own noise (the relMSE its
variance layer predicts; independent errors add, so this is the error against
the converged image, and the ratios use it), zero-contribution fraction, mean
path length, time per sample.

Scenes are shipped scene names or paths to any pbrt-v4 file (`--res` then
renders every image of the run at that size); the method `auto` is what a
user gets by default (`--guide auto`: the effects set decides, and the
learned mixture weight, roulette and NEE probability keep a guide that does
not pay out of the way). For the "guiding never costs" check:

    scripts/bench_guiding.py --methods none auto --scenes ../shared/public-scenes/cornell-box/cornell-box.pbrt ... \
        --res 160x120 --no-reference --time 4 --repeats 3

`--no-reference` judges each render by its own variance layer (the relMSE
it estimates, which for independent samples is unbiased for the error of
an unbiased render) instead of against a reference: no reference to pay
for, but fireflies a render did not draw are missed. Renders then use
independent samples (`--sampler independent`), whose variance estimate is
not inflated as stratified points' is.

The reference of each scene is an unguided render of --ref-spp samples per
pixel, made and cached by scripts/reference.py (its command and time are
recorded beside it), so re-runs only pay for it once. Results: out/bench-guiding/results.json and a
table on stdout with the issue-3 targets checked.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference as ref_cache  # noqa: E402

ROOT = ref_cache.ROOT
# Each method's render options (a method that is not here is a --guide value).
METHOD_ARGS = {"qtable-throughput": ["--guide", "qtable", "--guide-roulette", "throughput"]}
SCENES = ["cornell-box", "door-ajar", "shelter", "pillars", "glossy"]
# relMSE(qtable) / relMSE(none) targets from issue 3.
TARGETS = {"door-ajar": 0.25, "shelter": 0.5, "pillars": 0.5, "cornell-box": 1.1}


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def compare(tessera, image, reference):
    return json.loads(run([tessera, "compare", image, reference, "--json"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=os.path.join(ROOT, "build", "tessera"))
    ap.add_argument("--scenes", nargs="*", default=SCENES)
    ap.add_argument("--methods", nargs="*", default=["none", "qtable", "qlearning"])
    ap.add_argument("--time", type=float, default=10.0, help="seconds per render")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=8192)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--backend", default="embree", help="what renders every method (default embree: the 2-core CPU the figures in docs/ are for; on a GPU machine auto would render on the GPU, where the methods compare differently: docs/backends.md)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-guiding"))
    ap.add_argument("--results", default="results.json", help="file name of the results, in --out")
    ap.add_argument("--guide-args", default="", help="extra options for the guided methods, e.g. '--guide-budget 4'")
    ap.add_argument("--res", default="", help="WxH for every render of the run, references included")
    ap.add_argument("--no-reference", action="store_true",
                    help="judge renders by their own estimated relMSE (independent samples) instead of a reference")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    threads = ["--threads", str(a.threads)] if a.threads else []

    results = {"guide_args": a.guide_args, "time_budget_s": a.time, "repeats": a.repeats, "threads": a.threads or os.cpu_count(),
               "ref_spp": a.ref_spp, "scenes": {}}
    res = ["--res", a.res] if a.res else []
    for scene_arg in a.scenes:
        if scene_arg.endswith(".pbrt"):
            path = os.path.abspath(scene_arg)
            scene = os.path.splitext(os.path.basename(path))[0]
            parent = os.path.basename(os.path.dirname(path))
            if parent != scene:  # cornell-box/volumetric-caustic and volumetric-caustic/volumetric-caustic
                scene = f"{parent}-{scene}"
        else:
            path = os.path.join(ROOT, "scenes", scene_arg + ".pbrt")
            scene = scene_arg
        entry = {"methods": {}}
        if not a.no_reference:
            ref, meta = ref_cache.reference(path, spp=a.ref_spp, tessera=a.tessera, threads=a.threads, extra_args=res,
                                            log=lambda m: print(f"[{scene}] {m}", flush=True))
            entry["reference"] = {"spp": meta["spp"], "seconds": meta["seconds"], "noise": meta["estimated_relmse"]}
        sampler = ["--sampler", "independent"] if a.no_reference else []
        for method in a.methods:
            rows = []
            for rep in range(a.repeats):
                img = os.path.join(a.out, f"{scene}-{method}.exr")
                st = os.path.join(a.out, f"{scene}-{method}.json")
                extra = a.guide_args.split() if method != "none" else []
                method_args = METHOD_ARGS.get(method, ["--guide", method])
                run([a.tessera, "render", path, "-q", "--no-preview", *method_args, "--time", str(a.time),
                     "--seed", str(rep + 1), "--stats", st, "-o", img, *threads, *extra, *res, *sampler,
                     "--backend", a.backend])
                s = json.load(open(st))
                if a.no_reference:
                    c = {"relmse": s["estimated_relmse"], "reference_estimated_relmse": 0.0}
                else:
                    c = compare(a.tessera, img, ref)
                pixels = s["width"] * s["height"]
                # The reference's own noise adds to every measured relMSE (independent errors add);
                # subtracting its estimate leaves the error against the converged image.
                rows.append({"relmse": c["relmse"], "relmse_vs_truth": c["relmse"] - c["reference_estimated_relmse"],
                             "spp": s["spp"], "seconds": s["seconds"],
                             "zero_contribution_fraction": s["zero_contribution_fraction"],
                             "mean_path_length": s["mean_path_length"],
                             "ns_per_sample": s["seconds"] / max(1, s["spp"] * pixels) * 1e9,
                             "ns_per_vertex": s["seconds"] / max(1e-30, s["spp"] * pixels * s["mean_path_length"]) * 1e9})
            med = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
            med["runs"] = rows
            entry["methods"][method] = med
            print(f"[{scene}] {method:9s} relMSE {med['relmse']:.5g} (minus reference noise "
                  f"{med['relmse_vs_truth']:.5g})  spp {med['spp']:.0f}  "
                  f"zero {med['zero_contribution_fraction']:.3f}  path {med['mean_path_length']:.2f}  "
                  f"{med['ns_per_sample']:.0f} ns/sample", flush=True)
        results["scenes"][scene] = entry

    # Time per sample also grows with path length: guided roulette keeps paths
    # that find light alive longer. Time per path vertex shows the guide's own cost.
    print("\nrelMSE ratios are of the error against the converged image (measured minus the reference's own noise);"
          " raw = as measured")
    print("scene         relMSE qtable/none (raw)  target   time/sample qtable/none   time/vertex   qtable vs qlearning")
    for scene, e in results["scenes"].items():
        m = e["methods"]
        if "none" not in m or "qtable" not in m:
            continue
        ratio = m["qtable"]["relmse_vs_truth"] / max(m["none"]["relmse_vs_truth"], 1e-30)
        raw = m["qtable"]["relmse"] / max(m["none"]["relmse"], 1e-30)
        tps = m["qtable"]["ns_per_sample"] / max(m["none"]["ns_per_sample"], 1e-30)
        tpv = m["qtable"]["ns_per_vertex"] / max(m["none"]["ns_per_vertex"], 1e-30)
        target = TARGETS.get(scene)
        verdict = "" if target is None else ("ok" if ratio <= target else "MISSED")
        ql = ""
        if "qlearning" in m:
            ql = "sarsa better" if m["qtable"]["relmse_vs_truth"] < m["qlearning"]["relmse_vs_truth"] else "qlearning better"
        e["ratio_relmse_qtable_vs_none"] = ratio
        e["ratio_relmse_qtable_vs_none_raw"] = raw
        e["ratio_time_per_sample"] = tps
        e["ratio_time_per_vertex"] = tpv
        print(f"{scene:12s}  {ratio:8.3f} ({raw:.3f})      {('<= ' + str(target)) if target else '   -   ':8s} {verdict:6s}"
              f"  {tps:6.2f} (target <= 1.25)      {tpv:6.2f}        {ql}")
        if "qtable-throughput" in m:
            t = m["qtable-throughput"]
            e["ratio_relmse_throughput_roulette_vs_none"] = t["relmse_vs_truth"] / max(m["none"]["relmse_vs_truth"], 1e-30)
            e["ratio_time_per_sample_throughput_roulette"] = t["ns_per_sample"] / max(m["none"]["ns_per_sample"], 1e-30)
            print(f"{'':12s}  with throughput roulette: {e['ratio_relmse_throughput_roulette_vs_none']:8.3f}"
                  f"   time/sample {e['ratio_time_per_sample_throughput_roulette']:6.2f}")
    # The default (--guide auto) against plain path tracing: guiding must never cost.
    rows = [(scene, e) for scene, e in results["scenes"].items() if "auto" in e["methods"] and "none" in e["methods"]]
    if rows:
        print("\nscene                    relMSE auto/none (raw)   verdict (auto must not be worse than none)")
        for scene, e in rows:
            m = e["methods"]
            ratio = m["auto"]["relmse_vs_truth"] / max(m["none"]["relmse_vs_truth"], 1e-30)
            raw = m["auto"]["relmse"] / max(m["none"]["relmse"], 1e-30)
            e["ratio_relmse_auto_vs_none"] = ratio
            e["ratio_relmse_auto_vs_none_raw"] = raw
            print(f"{scene:24s} {ratio:8.3f} ({raw:.3f})        {'ok' if ratio <= 1.0 else 'WORSE'}")
    with open(os.path.join(a.out, a.results), "w") as f:
        json.dump(results, f, indent=2)
    print(f"\nwrote {os.path.join(a.out, a.results)}")


if __name__ == "__main__":
    main()
