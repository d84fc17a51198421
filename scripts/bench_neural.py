#!/usr/bin/env python3
"""Neural guide benchmark (not a test): --guide neural against qtable and
none, per shipped scene, at equal wall-clock time (training included) and
at equal samples.

Each render is judged by its own estimated relMSE (the variance layer of a
render with independent samples: unbiased for the error of an unbiased
render; `--reference` compares against scripts/reference.py's cached
references instead). Reported per scene and method, medians over
--repeats seeds:
  relMSE at equal time and at equal samples, time per sample and per path
  vertex, the guide's memory (network: parameters and Adam's moments), and
  the network's shares of the render's time in inference and training.
The issue's targets are checked at the end: network state <= 1 MB, time per
vertex <= 2x the table's, neural beats qtable at equal samples (door-ajar,
shelter), neural beats none at equal time (door-ajar, shelter, pillars).
Results: out/bench-neural/results.json and a table on stdout.

    scripts/bench_neural.py --time 20 --spp 64 --repeats 3
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
SCENES = ["cornell-box", "door-ajar", "shelter", "pillars", "glossy"]
METHODS = ["none", "qtable", "neural"]


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def render(a, path, method, budget, seed, ref, tag):
    img = os.path.join(a.out, f"{tag}.exr")
    st = os.path.join(a.out, f"{tag}.json")
    threads = ["--threads", str(a.threads)] if a.threads else []
    res = ["--res", a.res] if a.res else []
    sampler = [] if ref else ["--sampler", "independent"]
    run([a.tessera, "render", path, "-q", "--no-preview", "--guide", method, *budget, "--seed", str(seed),
         "--stats", st, "-o", img, *threads, *res, *sampler, "--backend", a.backend])
    s = json.load(open(st))
    if ref:
        relmse = json.loads(run([a.tessera, "compare", img, ref, "--json"]))["relmse"]
    else:
        relmse = s["estimated_relmse"]
    pixels = s["width"] * s["height"]
    samples = max(1, s["spp"] * pixels)
    row = {"relmse": relmse, "spp": s["spp"], "seconds": s["seconds"],
           "ns_per_sample": s["seconds"] * s["threads"] / samples * 1e9,
           "ns_per_vertex": s["seconds"] * s["threads"] / max(1e-30, samples * s["mean_path_length"]) * 1e9,
           "guide_bytes": s.get("guide_cache_bytes", 0)}
    if method == "neural":
        row["inference_fraction"] = s["guide_neural_inference_fraction"]
        row["train_fraction"] = s["guide_neural_train_fraction"]
        row["inference_us"] = s["guide_neural_inference_us"]
        row["loss"] = s["guide_neural_loss"]
    return row


def median_rows(rows):
    return {k: statistics.median(r[k] for r in rows) for k in rows[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=os.path.join(ROOT, "build", "tessera"))
    ap.add_argument("--scenes", nargs="*", default=SCENES)
    ap.add_argument("--time", type=float, default=20.0, help="seconds per equal-time render")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel of the equal-samples renders")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2, help="2: the CI machine's cores (0 = all)")
    ap.add_argument("--backend", default="embree", help="what renders every method (default embree: the 2-core CPU the figures in docs/ are for; on a GPU machine auto would render on the GPU, where the methods compare differently: docs/backends.md)")
    ap.add_argument("--res", default="", help="WxH for every render")
    ap.add_argument("--reference", action="store_true", help="judge against cached references (scripts/reference.py)")
    ap.add_argument("--ref-spp", type=int, default=8192)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-neural"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    results = {"time_budget_s": a.time, "spp": a.spp, "repeats": a.repeats, "threads": a.threads, "scenes": {}}
    for scene in a.scenes:
        path = os.path.join(ROOT, "scenes", scene + ".pbrt")
        ref = None
        if a.reference:
            res = ["--res", a.res] if a.res else []
            ref, _ = ref_cache.reference(path, spp=a.ref_spp, tessera=a.tessera, threads=a.threads, extra_args=res,
                                         log=lambda m: print(f"[{scene}] {m}", flush=True))
        entry = {"equal_time": {}, "equal_samples": {}}
        for method in METHODS:
            rows = [render(a, path, method, ["--time", str(a.time)], k + 1, ref, f"{scene}-{method}-time")
                    for k in range(a.repeats)]
            entry["equal_time"][method] = median_rows(rows)
            if method != "none":
                rows = [render(a, path, method, ["--spp", str(a.spp)], k + 1, ref, f"{scene}-{method}-spp")
                        for k in range(a.repeats)]
                entry["equal_samples"][method] = median_rows(rows)
            t = entry["equal_time"][method]
            extra = ""
            if method == "neural":
                extra = (f"  inference {t['inference_fraction']:.0%} ({t['inference_us']:.2f} us each)"
                         f"  training {t['train_fraction']:.0%}  loss {t['loss']:.3g}")
            print(f"[{scene}] {method:7s} equal time: relMSE {t['relmse']:.4g} spp {t['spp']:.0f}"
                  f"  {t['ns_per_sample']:.0f} ns/sample  {t['ns_per_vertex']:.0f} ns/vertex"
                  f"  guide {t['guide_bytes'] / 1048576:.2f} MB{extra}", flush=True)
        results["scenes"][scene] = entry

    print("\nscene        relMSE neural/none  neural/qtable  | equal spp: neural/qtable | vertex time neural/qtable"
          "  network MB")
    for scene, e in results["scenes"].items():
        t, s = e["equal_time"], e["equal_samples"]
        r_none = t["neural"]["relmse"] / max(t["none"]["relmse"], 1e-30)
        r_table = t["neural"]["relmse"] / max(t["qtable"]["relmse"], 1e-30)
        r_spp = s["neural"]["relmse"] / max(s["qtable"]["relmse"], 1e-30)
        r_vertex = t["neural"]["ns_per_vertex"] / max(t["qtable"]["ns_per_vertex"], 1e-30)
        mb = t["neural"]["guide_bytes"] / 1048576
        e.update({"ratio_relmse_neural_vs_none": r_none, "ratio_relmse_neural_vs_qtable": r_table,
                  "ratio_relmse_neural_vs_qtable_equal_spp": r_spp, "ratio_time_per_vertex_neural_vs_qtable": r_vertex})
        print(f"{scene:12s} {r_none:10.3f}  {r_table:13.3f}   | {r_spp:12.3f}            | {r_vertex:10.2f}"
              f"             {mb:6.2f}")
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(results, f, indent=2)
    print(f"\nwrote {os.path.join(a.out, 'results.json')}")


if __name__ == "__main__":
    main()
