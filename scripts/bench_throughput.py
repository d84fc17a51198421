#!/usr/bin/env python3
"""Throughput benchmark (not a test): Tessera versus Embree on the Cornell box.

Reports, in one run:
  * our samples/s and rays/s on the built-in Cornell box (256x256, max depth 8);
  * (a) Embree's tutorial path tracer (Debian embree-tools `pathtracer`) on the
    Cornell box OBJ it ships, at equal resolution, spp and path length, and our
    samples/s divided by its samples/s;
  * (b) raw Embree rtcIntersect1 throughput on random incoherent rays in our
    scene (`tessera bench-rays`), and our rays/s divided by it;
  * the effects-set specialisation: diffuse-only Cornell box with its own
    specialisation versus the integrator compiled for every effect.
Samples/s of both renderers are measured the same way: wall-clock difference
between a long and a short render, so start-up and scene loading cancel out.
Each figure is the median of --repeats runs. Guiding is off (--guide none):
Embree's tutorial does not guide, and issue 3's benchmark measures guiding.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EMBREE_MODELS = "/usr/share/doc/embree3/models"


def wall(cmd):
    t = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t


def differential_rate(make_cmd, spp_lo, spp_hi, pixels, repeats):
    rates = []
    for _ in range(repeats):
        t_lo = wall(make_cmd(spp_lo))
        t_hi = wall(make_cmd(spp_hi))
        rates.append((spp_hi - spp_lo) * pixels / max(t_hi - t_lo, 1e-9))
    return statistics.median(rates)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=os.path.join(ROOT, "build", "tessera"))
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--depth", type=int, default=8)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--rays", type=int, default=20_000_000)
    ap.add_argument("--json", help="also write the results here")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="tessera_bench_")
    pixels = a.res * a.res
    spp_lo = max(1, a.spp // 8)
    res = {"resolution": a.res, "spp": a.spp, "max_depth": a.depth, "threads": a.threads, "repeats": a.repeats}

    def ours(spp, extra=()):
        return [a.tessera, "render", "-q", "--no-preview", "--res", f"{a.res}x{a.res}", "--spp", str(spp),
                "--max-depth", str(a.depth), "--threads", str(a.threads), "--guide", "none", "--spectral", "off",
                "-o", os.path.join(tmp, "o.exr"), *extra]

    # Our own stats (render loop only) for rays/s and path statistics.
    stats_runs = []
    for _ in range(a.repeats):
        sp = os.path.join(tmp, "s.json")
        subprocess.run(ours(a.spp, ["--stats", sp]), check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        stats_runs.append(json.load(open(sp)))
    res["ours_rays_per_s"] = statistics.median(s["rays_per_second"] for s in stats_runs)
    res["ours_samples_per_s_render_loop"] = statistics.median(s["samples_per_second"] for s in stats_runs)
    res["ours_mean_path_length"] = stats_runs[0]["mean_path_length"]
    res["ours_samples_per_s"] = differential_rate(lambda s: ours(s), spp_lo, a.spp, pixels, a.repeats)

    if os.path.exists("/usr/bin/pathtracer"):
        ecs = os.path.join(EMBREE_MODELS, "cornell_box.ecs")

        def embree(spp):
            return ["pathtracer", "-c", ecs, "-o", os.path.join(tmp, "e.ppm"), "--size", str(a.res), str(a.res),
                    "--spp", str(spp), "--max-path-length", str(a.depth), "--threads", str(a.threads)]

        res["embree_tutorial_samples_per_s"] = differential_rate(embree, spp_lo, a.spp, pixels, a.repeats)
        res["ratio_samples_vs_embree_tutorial"] = res["ours_samples_per_s"] / res["embree_tutorial_samples_per_s"]
    else:
        print("embree-tools' pathtracer not found: skipping (a)", file=sys.stderr)

    raw = []
    for _ in range(a.repeats):
        out = subprocess.run([a.tessera, "bench-rays", "--rays", str(a.rays), "--threads", str(a.threads)],
                             check=True, capture_output=True, text=True).stdout
        raw.append(json.loads(out)["rays_per_second"])
    res["raw_rtcIntersect1_rays_per_s"] = statistics.median(raw)
    res["ratio_rays_vs_raw_embree"] = res["ours_rays_per_s"] / res["raw_rtcIntersect1_rays_per_s"]

    full = differential_rate(lambda s: ours(s, ["--full-specialisation"]), spp_lo, a.spp, pixels, a.repeats)
    res["ours_samples_per_s_full_specialisation"] = full
    res["specialisation_speedup"] = res["ours_samples_per_s"] / full

    print(json.dumps(res, indent=2))
    print(f"samples/s: ours {res['ours_samples_per_s']/1e6:.3f} M", end="")
    if "embree_tutorial_samples_per_s" in res:
        print(f", Embree tutorial {res['embree_tutorial_samples_per_s']/1e6:.3f} M -> ratio "
              f"{res['ratio_samples_vs_embree_tutorial']:.2f} (target >= 1.0)")
    print(f"rays/s: ours {res['ours_rays_per_s']/1e6:.2f} M, raw rtcIntersect1 "
          f"{res['raw_rtcIntersect1_rays_per_s']/1e6:.2f} M -> ratio {res['ratio_rays_vs_raw_embree']:.2f} (target >= 0.7)")
    print(f"effects specialisation (diffuse-only Cornell box): {res['specialisation_speedup']:.2f}x faster than the full integrator")
    if a.json:
        json.dump(res, open(a.json, "w"), indent=2)


if __name__ == "__main__":
    main()
