#!/usr/bin/env python3
"""Render-farm benchmark (not a test): scaling and shared guiding under mpirun.

On one machine, with one rendering thread per rank (so ranks = cores used):
  strong   fixed work (--spp), 1..N ranks: speed-up and efficiency T1 / (N TN)
  weak     work proportional to ranks (--spp per rank): efficiency T1 / TN
  sync     equal wall-clock time, N ranks, --guide-sync pass versus off:
           relMSE against a reference, and the share of time spent in the
           guide's reductions
N defaults to the machine's core count. Writes out/bench-farm/results.csv and
out/bench-farm/scaling.png (matplotlib), and prints a table.
The reference for the sync comparison comes from scripts/reference.py's
cache (rendered there, unguided, --ref-spp, on first use).
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference as ref_cache  # noqa: E402

ROOT = ref_cache.ROOT
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def render(a, ranks, args, name):
    exr = os.path.join(a.out, name + ".exr")
    js = os.path.join(a.out, name + ".json")
    cmd = [a.tessera, "render", a.scene_path, "-q", "--no-preview", "--threads", "1", "-o", exr, "--stats", js] + args
    if ranks > 0:  # 0: a plain local process
        # mpirun's default binding (a core per rank here): unbound ranks
        # migrate between cores and lose their caches, measured 0.80 instead
        # of 0.93 strong-scaling efficiency with guiding on 2 cores.
        cmd = ["mpirun", "-np", str(ranks)] + cmd
    t0 = time.perf_counter()
    run(cmd)
    wall = time.perf_counter() - t0
    stats = json.load(open(js))
    stats["wall"] = wall
    stats["exr"] = exr
    return stats


def median_render(a, ranks, args, name):
    runs = [render(a, ranks, args, name) for _ in range(a.repeats)]
    runs.sort(key=lambda s: s["seconds"])
    return runs[len(runs) // 2]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=os.path.join(ROOT, "build", "tessera"))
    ap.add_argument("--scene", default="door-ajar")
    ap.add_argument("--max-ranks", type=int, default=os.cpu_count())
    ap.add_argument("--spp", type=int, default=64, help="strong scaling: samples per pixel in all")
    ap.add_argument("--spp-per-rank", type=int, default=32, help="weak scaling")
    ap.add_argument("--time", type=float, default=10.0, help="sync comparison: seconds per render")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=8192)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-farm"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    a.scene_path = os.path.join(ROOT, "scenes", a.scene + ".pbrt")
    seed = ["--seed", "11"]
    rows = []
    n_max = max(1, a.max_ranks)
    print(f"machine: {os.cpu_count()} cores; ranks 1..{n_max}, 1 rendering thread each; medians of {a.repeats}")

    # Strong and weak scaling.
    base = {}
    for kind in ("strong", "weak"):
        for n in range(1, n_max + 1):
            spp = a.spp if kind == "strong" else a.spp_per_rank * n
            s = median_render(a, n, ["--spp", str(spp)] + seed, f"{kind}-{n}")
            if n == 1:
                base[kind] = s["seconds"]
            eff = base[kind] / (n * s["seconds"]) if kind == "strong" else base[kind] / s["seconds"]
            rows.append({"kind": kind, "ranks": n, "spp": spp, "seconds": s["seconds"], "efficiency": eff,
                         "guide_sync_fraction": s.get("guide_sync_fraction", 0.0), "relmse": ""})
            print(f"{kind:6s} ranks {n}: {spp} spp in {s['seconds']:.2f} s, efficiency {eff:.3f}, "
                  f"guide sync {100 * s.get('guide_sync_fraction', 0.0):.2f} % of the time", flush=True)

    # Shared versus per-rank guiding at equal time.
    ref, _ = ref_cache.reference(a.scene_path, spp=a.ref_spp, tessera=a.tessera, log=lambda m: print(m, flush=True))
    n = max(2, n_max)
    for sync in ("pass", "off", "none"):
        errs, fracs = [], []
        for rep in range(a.repeats):
            args = ["--time", str(a.time), "--seed", str(100 + rep)]
            args += ["--guide", "none"] if sync == "none" else ["--guide-sync", sync]
            s = render(a, n, args, f"sync-{sync}")
            cmp = json.loads(run([a.tessera, "compare", s["exr"], ref, "--json"]))
            errs.append(cmp["relmse"])
            fracs.append(s.get("guide_sync_fraction", 0.0))
        rows.append({"kind": f"sync-{sync}", "ranks": n, "spp": "", "seconds": a.time, "efficiency": "",
                     "guide_sync_fraction": statistics.median(fracs), "relmse": statistics.median(errs)})
        print(f"equal time {a.time:.0f} s, {n} ranks, guide {'none' if sync == 'none' else 'sync ' + sync}: "
              f"relMSE {statistics.median(errs):.5f} (runs {', '.join(f'{e:.5f}' for e in errs)})", flush=True)

    with open(os.path.join(a.out, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print("wrote", os.path.join(a.out, "results.csv"))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing (scripts/install-deps.sh installs it): no plot")
        return
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for kind, style in (("strong", "o-"), ("weak", "s-")):
        r = [x for x in rows if x["kind"] == kind]
        ax1.plot([x["ranks"] for x in r], [x["efficiency"] for x in r], style, label=kind)
    ax1.axhline(0.9, color="gray", ls=":", label="0.9 target")
    ax1.set_xlabel("ranks (1 thread each)")
    ax1.set_ylabel("parallel efficiency")
    ax1.set_ylim(0, 1.1)
    ax1.legend()
    ax1.set_title(f"{a.scene}: scaling on {os.cpu_count()} cores")
    r = [x for x in rows if x["kind"].startswith("sync-")]
    ax2.bar([x["kind"][5:] for x in r], [x["relmse"] for x in r])
    ax2.set_ylabel("relMSE (median)")
    ax2.set_title(f"{n} ranks, {a.time:.0f} s: guide sync pass / off / no guide")
    fig.tight_layout()
    png = os.path.join(a.out, "scaling.png")
    fig.savefig(png, dpi=100)
    print("wrote", png)


if __name__ == "__main__":
    main()
