#!/usr/bin/env python3
"""What accuracy costs in time, for every shipped scene and method.

Regenerates docs/accuracy.md and its plots (docs/accuracy/); scripts/accuracy.sh
installs, builds and runs this in one command. For each scene:

1. Reference: plain path tracing at --ref-spp samples per pixel, cached
   (scripts/reference.py records its command and duration).
2. Convergence: each method (--guide none, qtable, qlearning) renders for the
   same wall-clock budget --time, training included, writing a snapshot at
   every doubling of the sample count. relMSE and MAPE of every snapshot
   against the reference, and the renderer's own estimate, go to
   convergence.csv. Times are render time: wall clock minus the time spent
   writing snapshots.
3. Time to error: the seconds each method needs to reach the relMSE plain
   path tracing reaches at a quarter of the budget and at the full budget
   (log-log interpolation between snapshots; a curve ending just above it is
   extended along relMSE ~ 1/t, and marked), and the speed-up over plain
   path tracing.
4. Stopping rule: with --target-error E (E = twice plain path tracing's final
   relMSE, at least 5x the reference's own noise) and a time limit, the true
   relMSE at stop over E, for plain and guided rendering, --stop-repeats
   seeds each.
Plots: error versus time (log-log), zero-contribution fraction and mean path
length per pass, estimated versus measured relMSE.
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference as ref_cache  # noqa: E402

ROOT = ref_cache.ROOT
SCENES = ["cornell-box", "door-ajar", "shelter", "pillars", "glossy"]
METHODS = ["none", "qtable", "qlearning", "neural"]
GUIDED_DEFAULT = "qtable"  # what `tessera render` uses on scenes where guiding helps
LABELS = {"none": "plain path tracing", "qtable": "qtable (expected SARSA)", "qlearning": "qlearning (max)",
          "neural": "neural (MLP, expected SARSA)"}


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    return r.stdout, r.stderr


def compare(tessera, image, reference):
    return json.loads(run([tessera, "compare", image, reference, "--json"])[0])


def loglog_interp(x0, y0, x1, y1, y):
    """x where the segment (x0,y0)-(x1,y1), straight on a log-log plot, reaches y."""
    if y0 <= 0 or y1 <= 0 or x0 <= 0 or x1 <= 0 or y0 == y1:
        return x1
    t = (math.log(y) - math.log(y0)) / (math.log(y1) - math.log(y0))
    return math.exp(math.log(x0) + t * (math.log(x1) - math.log(x0)))


def time_to_error(points, target):
    """(seconds, extrapolated): the first time the curve reaches target. A
    curve that ends above it (by at most 2x) is extended along relMSE ~ 1/t,
    Monte Carlo's rate, and marked extrapolated; (None, False) beyond that."""
    prev = None
    for p in points:
        if p["relmse"] <= target:
            if prev is None:
                return p["seconds"], False
            return loglog_interp(prev["seconds"], prev["relmse"], p["seconds"], p["relmse"], target), False
        prev = p
    last = points[-1]
    if last["relmse"] <= 2 * target:
        return last["seconds"] * last["relmse"] / target, True
    return None, False


def error_at_time(points, t):
    """relMSE of the curve at time t (log-log interpolation)."""
    for a, b in zip(points, points[1:]):
        if a["seconds"] <= t <= b["seconds"]:
            u = (math.log(t) - math.log(a["seconds"])) / (math.log(b["seconds"]) - math.log(a["seconds"]))
            return math.exp(math.log(a["relmse"]) + u * (math.log(b["relmse"]) - math.log(a["relmse"])))
    return points[-1]["relmse"]


def convergence_run(a, scene, scene_path, method, ref):
    """Renders `method` for the budget with doubling snapshots; returns (points, stats)."""
    stem = os.path.join(a.out, f"{scene}-{method}")
    shutil.rmtree(stem + "-snapshots", ignore_errors=True)
    cmd = [a.tessera, "render", scene_path, "-q", "--no-preview", "--guide", method, "--time", str(a.time),
           "--seed", str(a.seed), "--snapshot-every", "doubling", "--stats", stem + ".json", "-o", stem + ".exr",
           *a.thread_args, "--backend", a.backend]
    run(cmd)
    with open(stem + ".json") as f:
        stats = json.load(f)
    shots = [dict(s) for s in stats.get("snapshots", [])]
    final = {"file": stem + ".exr", "spp": stats["spp"], "render_seconds": stats["seconds"] - stats["pass_end_seconds"],
             "estimated_relmse": stats["estimated_relmse"]}
    if not shots or shots[-1]["spp"] != final["spp"]:
        shots.append(final)
    points = []
    for s in shots:
        c = compare(a.tessera, s["file"], ref)
        points.append({"scene": scene, "method": method, "spp": s["spp"], "seconds": s["render_seconds"],
                       "relmse": c["relmse"], "mape": c["mape"], "estimated_relmse": s["estimated_relmse"],
                       "nonfinite_pixels": c["nonfinite_pixels"]})
    return points, stats


def stop_run(a, scene, scene_path, method, ref, target, seed):
    """Renders with --target-error (time limit 2x the budget); returns what it stopped at."""
    stem = os.path.join(a.out, f"{scene}-{method}-target")
    cmd = [a.tessera, "render", scene_path, "-q", "--no-preview", "--guide", method, "--target-error", f"{target:.6g}",
           "--time", str(2 * a.time), "--seed", str(seed), "--stats", stem + ".json", "-o", stem + ".exr",
           *a.thread_args, "--backend", a.backend]
    run(cmd)
    with open(stem + ".json") as f:
        stats = json.load(f)
    c = compare(a.tessera, stem + ".exr", ref)
    return {"scene": scene, "method": method, "seed": seed, "target": target, "stop_reason": stats["stop_reason"],
            "spp": stats["spp"], "seconds": stats["seconds"], "estimated_relmse": stats["estimated_relmse"],
            "relmse": c["relmse"], "reference_noise": c["reference_estimated_relmse"]}


def plot(a, results, docs_dir):
    import matplotlib  # main() checked that it imports
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = list(results["scenes"])
    colors = {"none": "black", "qtable": "tab:blue", "qlearning": "tab:orange", "neural": "tab:green"}
    files = []

    def save(fig, name):
        fig.tight_layout()
        files.append(os.path.join(docs_dir, name))
        fig.savefig(files[-1], dpi=90)
        plt.close(fig)

    fig, axes = plt.subplots(1, len(scenes), figsize=(4 * len(scenes), 3.6), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        e = results["scenes"][scene]
        for m, pts in e["curves"].items():
            ax.loglog([p["seconds"] for p in pts], [p["relmse"] for p in pts], "o-", ms=3, color=colors.get(m), label=m)
        ax.axhline(e["reference"]["estimated_relmse"], ls=":", color="gray", label="reference noise")
        ax.set_title(scene)
        ax.set_xlabel("render time [s]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("relMSE vs reference")
    axes[0][0].legend(fontsize=8)
    save(fig, "error-vs-time.png")

    fig, axes = plt.subplots(2, len(scenes), figsize=(4 * len(scenes), 6), squeeze=False)
    for col, scene in enumerate(scenes):
        for m, st in results["scenes"][scene]["per_pass"].items():
            spp = []
            total = 0
            for p in st:
                total += p["spp"]
                spp.append(total)
            axes[0][col].semilogx(spp, [p["zero_contribution_fraction"] for p in st], color=colors.get(m), label=m)
            axes[1][col].semilogx(spp, [p["mean_path_length"] for p in st], color=colors.get(m), label=m)
        axes[0][col].set_title(scene)
        axes[1][col].set_xlabel("samples per pixel (end of pass)")
        for r in (0, 1):
            axes[r][col].grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("zero-contribution fraction")
    axes[1][0].set_ylabel("mean path length")
    axes[0][0].legend(fontsize=8)
    save(fig, "training.png")

    fig, ax = plt.subplots(figsize=(5, 4.5))
    lo, hi = 1e9, 0
    for scene in scenes:
        e = results["scenes"][scene]
        noise = e["reference"]["estimated_relmse"]
        xs, ys = [], []
        for m, pts in e["curves"].items():
            for p in pts:
                true = p["relmse"] - noise
                if p["estimated_relmse"] > 0 and true > 0:
                    xs.append(true)
                    ys.append(p["estimated_relmse"])
        ax.loglog(xs, ys, "o", ms=3, label=scene)
        if xs:
            lo, hi = min(lo, *xs, *ys), max(hi, *xs, *ys)
    if hi > 0:
        ax.loglog([lo, hi], [lo, hi], "k-", lw=0.8, label="estimate = truth")
        ax.loglog([lo, hi], [lo / 1.5, hi / 1.5], "k:", lw=0.8, label="factor 1.5")
        ax.loglog([lo, hi], [lo * 1.5, hi * 1.5], "k:", lw=0.8)
    ax.set_xlabel("measured relMSE minus reference noise")
    ax.set_ylabel("estimated relMSE (while rendering)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, "estimate-vs-measured.png")
    return files


def fmt_s(t, budget, extrapolated=False):
    return f"> {2 * budget:.0f}" if t is None else (f"{t:.1f}*" if extrapolated else f"{t:.2f}")


def stop_summary(stops):
    f = sorted(s["factor"] for s in stops)
    inside = sum(s["within"] for s in stops)
    return (f"{inside} of {len(stops)} stops within a factor 1.5; factors from {f[0]:.2f} to {f[-1]:.2f}, "
            f"median {f[len(f) // 2]:.2f}.")


def write_docs(a, results, plots, docs_md):
    r = results
    L = []
    L.append("# What accuracy costs in time\n")
    L.append("<!-- Generated by scripts/accuracy.sh (scripts/accuracy.py); do not edit by hand. -->\n")
    L.append(f"Regenerate everything on this page (tables, plots, `accuracy/convergence.csv`) with\n\n"
             f"```\nscripts/accuracy.sh\n```\n\n"
             f"It installs what is missing, builds, and runs `scripts/accuracy.py` (options: `--help`). "
             f"On the machine below it took **{r['wall_minutes']:.1f} minutes** with the references cached; "
             f"rendering the five references the first time adds about "
             f"**{sum(e['reference']['seconds'] for e in r['scenes'].values()) / 60:.0f} minutes** "
             f"(they are cached in `out/references/` afterwards).\n")
    L.append(f"Machine: {r['machine']}. Budget per render: {r['time']:.0f} s wall clock, training included, "
             f"{r['threads']} threads, seed {r['seed']}. One run per method and scene: the figures carry "
             f"Monte Carlo noise of a few percent (more where fireflies dominate, e.g. shelter).\n")

    L.append("## How the numbers are made\n")
    L.append("- **relMSE** (what the stopping rule uses): mean over pixels and channels of "
             "(A − F)² / (F² + 0.01), A the image, F the reference. **MAPE**: mean over pixels of |A − F| / F on "
             "luminance, skipping black reference pixels. Pixels with NaN/Inf are counted and reported "
             "(`tessera compare`), not averaged.\n"
             "- **References**: plain path tracing (`--guide none`, NEE + MIS) at "
             f"{r['ref_spp']} spp with a seed no other run uses, made and cached by `scripts/reference.py`, "
             "which records the command and its duration beside each EXR. A reference is itself noisy: the "
             "relMSE its own variance layer predicts (*reference noise* below) is part of every measured "
             "relMSE, about additively, and shows as the dotted floor in the plots.\n"
             "- **Convergence curves**: `tessera render --time T --snapshot-every doubling` writes the image at "
             "1, 2, 4, … spp; each snapshot is compared with the reference. Time is render time: wall clock since "
             "the start minus time spent writing snapshots.\n"
             "- **In-render estimate**: after every pass, each pixel's sample variance gives the variance of its "
             "mean, Var = s²/n. The estimate is the mean over pixels and channels of Var / (max(m² − Var, 0) + 0.01), "
             "m the pixel's mean: the relMSE the image expects against the converged image (m² − Var estimates F² "
             "without bias, so a pixel lit by one rare bright sample counts as noisy, not as bright). It needs "
             "4 spp. `tessera render` shows it beside the ETA, writes it to the EXR metadata (`estimated_relmse`) "
             "and the stats JSON (final and per pass). Guided passes stay unbiased, so pooling their samples is "
             "sound. It underestimates where rare, very bright paths dominate and have not been sampled yet, "
             "and it overstates the error of stratified samples (the Sobol points of pbrt-v4's default samplers "
             "converge faster than the per-pixel variance says): there the estimate, and `--target-error`, are "
             "conservative. The shipped scenes use `Sampler \"independent\"`, so the figures below are for "
             "independent samples. The Cornell box's light is orange, so `--spectral auto` renders it with "
             "spectral transport; the other four scenes are RGB.\n"
             "- **Stopping**: `--target-error E` stops after the first pass whose estimate is ≤ E; with `--time` "
             "or `--spp` as well, whichever comes first, and the log says which (`stop_reason` in the stats).\n")

    L.append("## References\n")
    L.append("| scene | spp | seconds | threads | reference noise (relMSE) | command |")
    L.append("|---|---|---|---|---|---|")
    for scene, e in r["scenes"].items():
        rf = e["reference"]
        L.append(f"| {scene} | {rf['spp']} | {rf['seconds']:.0f} | {rf['threads']} | {rf['estimated_relmse']:.3g} | "
                 f"`{rf['command']}` |")
    L.append("")

    L.append(f"## Error after {r['time']:.0f} s\n")
    L.append("| scene | method | spp | relMSE | MAPE | estimated relMSE | relMSE / plain |")
    L.append("|---|---|---|---|---|---|---|")
    for scene, e in r["scenes"].items():
        base = e["curves"]["none"][-1]["relmse"] if "none" in e["curves"] else None
        for m, pts in e["curves"].items():
            p = pts[-1]
            ratio = f"{p['relmse'] / base:.2f}" if base else "–"
            L.append(f"| {scene} | {m} | {p['spp']} | {p['relmse']:.4g} | {p['mape']:.4g} | "
                     f"{p['estimated_relmse']:.4g} | {ratio} |")
    L.append("")

    L.append("## Time to error\n")
    L.append("Seconds each method needs to reach the relMSE plain path tracing reaches after a quarter of the "
             "budget (E¼) and after the whole budget (E₁), and the speed-up over plain path tracing "
             "(its time / the method's time). *: the method ended the budget above the error (by at most 2×); "
             "its time is extended along relMSE ∝ 1/t, the Monte Carlo rate.\n")
    L.append("| scene | E¼ | E₁ | method | seconds to E¼ | speed-up | seconds to E₁ | speed-up |")
    L.append("|---|---|---|---|---|---|---|---|")
    for scene, e in r["scenes"].items():
        tt = e.get("time_to_error")
        if not tt:
            continue
        for m, row in tt["methods"].items():
            def su(x):
                return "–" if x is None else f"{x:.2f}×"
            L.append(f"| {scene} | {tt['e_quarter']:.3g} | {tt['e_full']:.3g} | {m} | "
                     f"{fmt_s(row['t_quarter'], r['time'], row['x_quarter'])} | {su(row['speedup_quarter'])} | "
                     f"{fmt_s(row['t_full'], r['time'], row['x_full'])} | {su(row['speedup_full'])} |")
    L.append("")

    L.append("## The stopping rule\n")
    L.append("`tessera render --target-error E --time 2T`, E = max(2 × plain path tracing's relMSE after T, "
             "5 × reference noise). *Factor* = true relMSE at stop / E, where the true relMSE is the measured one "
             "minus the reference's own noise (the raw measured value is shown too). Within a factor 1.5 means "
             "0.67 ≤ factor ≤ 1.5.\n")
    L.append(f"{r['stop_repeats']} seeds per scene and method. " + stop_summary(r["stops"]) + "\n")
    L.append("| scene | method | seed | E | stopped by | spp | seconds | estimated at stop | measured | factor (raw) | "
             "within 1.5 |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for s in r["stops"]:
        L.append(f"| {s['scene']} | {s['method']} | {s['seed']} | {s['target']:.3g} | {s['stop_reason']} | {s['spp']} | "
                 f"{s['seconds']:.1f} | {s['estimated_relmse']:.3g} | {s['relmse']:.3g} | "
                 f"{s['factor']:.2f} ({s['factor_raw']:.2f}) | {'yes' if s['within'] else '**no**'} |")
    L.append("")

    L.append("## Plots\n")
    captions = {"error-vs-time.png": "relMSE against the reference versus render time (log–log); dotted: the "
                                     "reference's own noise.",
                "training.png": "Zero-contribution fraction and mean path length per pass: what the guide learns.",
                "estimate-vs-measured.png": "The in-render estimate versus the measured relMSE (minus reference "
                                            "noise) for every snapshot of every run."}
    for p in plots:
        name = os.path.basename(p)
        L.append(f"![{name}](accuracy/{name})\n\n{captions.get(name, '')}\n")
    L.append("The raw points are in [`accuracy/convergence.csv`](accuracy/convergence.csv) "
             "(scene, method, spp, seconds, relmse, mape, estimated_relmse).\n")
    with open(docs_md, "w") as f:
        f.write("\n".join(L))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=ref_cache.DEFAULT_TESSERA)
    ap.add_argument("--scenes", nargs="*", default=SCENES)
    ap.add_argument("--methods", nargs="*", default=METHODS)
    ap.add_argument("--time", type=float, default=30.0, help="wall-clock seconds per render")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=0, help="0 = all cores")
    ap.add_argument("--backend", default="embree", help="what renders every method (default embree: the 2-core CPU the figures in docs/ are for; on a GPU machine auto would render on the GPU, where the methods compare differently: docs/backends.md)")
    ap.add_argument("--stop-repeats", type=int, default=3, help="seeds per scene and method for the stopping rule")
    ap.add_argument("--ref-spp", type=int, default=ref_cache.DEFAULT_SPP)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "accuracy"), help="renders and snapshots")
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs"), help="where accuracy.md and accuracy/ go")
    a = ap.parse_args()
    try:  # checked before an hour of rendering, not after: without it the plots in docs/accuracy/ would go stale
        import matplotlib  # noqa: F401
    except ImportError:
        sys.exit(f"accuracy.py: {sys.executable} has no matplotlib for the plots (scripts/install-deps.sh installs "
                 "python3-matplotlib; scripts/accuracy.sh runs it with Debian's /usr/bin/python3)")
    if "none" not in a.methods:
        sys.exit("--methods must include none: speed-ups and targets are relative to plain path tracing")
    a.thread_args = ["--threads", str(a.threads)] if a.threads else []
    os.makedirs(a.out, exist_ok=True)
    docs_dir = os.path.join(a.docs, "accuracy")
    os.makedirs(docs_dir, exist_ok=True)
    t_start = time.perf_counter()
    reference_wall = 0.0

    results = {"time": a.time, "seed": a.seed, "stop_repeats": a.stop_repeats, "ref_spp": a.ref_spp, "threads": a.threads or os.cpu_count(),
               "machine": f"{os.cpu_count()} cores, {os.uname().machine}", "scenes": {}, "stops": []}
    rows = []
    for scene in a.scenes:
        path = os.path.join(ROOT, "scenes", scene + ".pbrt")
        t_ref = time.perf_counter()
        ref, meta = ref_cache.reference(path, spp=a.ref_spp, tessera=a.tessera, threads=a.threads,
                                        log=lambda m: print(f"[{scene}] {m}", flush=True))
        reference_wall += time.perf_counter() - t_ref  # rendering references is not part of the run's time
        e = {"reference": meta, "curves": {}, "per_pass": {}}
        for method in a.methods:
            points, stats = convergence_run(a, scene, path, method, ref)
            e["curves"][method] = points
            e["per_pass"][method] = stats["per_pass"]
            rows += points
            p = points[-1]
            print(f"[{scene}] {method:9s} {p['spp']:5d} spp in {p['seconds']:.1f}s  relMSE {p['relmse']:.4g}  "
                  f"MAPE {p['mape']:.4g}  estimated {p['estimated_relmse']:.4g}", flush=True)

        # Time to error, against plain path tracing's errors at T/4 and T.
        none = e["curves"]["none"]
        e_full = none[-1]["relmse"]
        e_quarter = error_at_time(none, a.time / 4)
        tt = {"e_quarter": e_quarter, "e_full": e_full, "methods": {}}
        t_none_q, t_none_f = time_to_error(none, e_quarter)[0], time_to_error(none, e_full)[0]
        for m, pts in e["curves"].items():
            (tq, xq), (tf, xf) = time_to_error(pts, e_quarter), time_to_error(pts, e_full)
            tt["methods"][m] = {"t_quarter": tq, "t_full": tf, "x_quarter": xq, "x_full": xf,
                                "speedup_quarter": (t_none_q / tq) if (tq and t_none_q) else None,
                                "speedup_full": (t_none_f / tf) if (tf and t_none_f) else None}
        e["time_to_error"] = tt

        # The stopping rule, plain and guided.
        target = max(2 * e_full, 5 * meta["estimated_relmse"])
        for m in [x for x in ("none", GUIDED_DEFAULT) if x in a.methods]:
            for rep in range(a.stop_repeats):
                s = stop_run(a, scene, path, m, ref, target, a.seed + 100 + rep)
                s["factor_raw"] = s["relmse"] / target
                s["factor"] = (s["relmse"] - s["reference_noise"]) / target
                s["within"] = 1 / 1.5 <= s["factor"] <= 1.5 and s["stop_reason"] == "target-error"
                results["stops"].append(s)
                print(f"[{scene}] --target-error {target:.3g} ({m}, seed {s['seed']}): stopped by {s['stop_reason']} "
                      f"at {s['spp']} spp, {s['seconds']:.1f}s; estimated {s['estimated_relmse']:.3g}, measured "
                      f"{s['relmse']:.3g}, factor {s['factor']:.2f} (raw {s['factor_raw']:.2f})", flush=True)
        results["scenes"][scene] = e

    with open(os.path.join(docs_dir, "convergence.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["scene", "method", "spp", "seconds", "relmse", "mape", "estimated_relmse",
                                          "nonfinite_pixels"])
        w.writeheader()
        for p in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in p.items()})
    plots = plot(a, results, docs_dir)
    results["wall_minutes"] = (time.perf_counter() - t_start - reference_wall) / 60
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(results, f, indent=2)
    write_docs(a, results, plots, os.path.join(a.docs, "accuracy.md"))

    print("\ntime to error (seconds; speed-up over plain path tracing):")
    for scene, e in results["scenes"].items():
        tt = e["time_to_error"]
        for m, row in tt["methods"].items():
            print(f"  {scene:12s} {m:9s} to E1/4={tt['e_quarter']:.3g}: "
                  f"{fmt_s(row['t_quarter'], a.time, row['x_quarter']):>6s}s"
                  f"  to E1={tt['e_full']:.3g}: {fmt_s(row['t_full'], a.time, row['x_full']):>6s}s"
                  f"  speed-up " + ("-" if row['speedup_full'] is None else f"{row['speedup_full']:.2f}x"))
    print("\nstopping rule (true relMSE at stop / target):")
    for s in results["stops"]:
        print(f"  {s['scene']:12s} {s['method']:9s} seed {s['seed']}  {s['factor']:.2f} (raw {s['factor_raw']:.2f}) "
              f"{'ok' if s['within'] else 'OUTSIDE 1.5'}")
    print("  " + stop_summary(results["stops"]))
    print(f"\nwrote {os.path.relpath(os.path.join(a.docs, 'accuracy.md'), ROOT)} "
          f"in {results['wall_minutes']:.1f} minutes")


if __name__ == "__main__":
    main()
