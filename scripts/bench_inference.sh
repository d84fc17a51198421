#!/usr/bin/env bash
# One neural-guide inference timed alone, against the built library
# (scripts/bench_inference.cpp): axis-aligned and random normals, without
# and with 6 learned lights (shelter's). Needs a build (scripts/build.sh).
# Renders' own figure is guide_neural_inference_us (scripts/bench_neural.py).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
[ -f "$build/libtessera_guidecache.a" ] || { echo "bench_inference: no $build/libtessera_guidecache.a (run scripts/build.sh first)" >&2; exit 1; }
bin=$(mktemp -d)/bench_inference
trap 'rm -rf "$(dirname "$bin")"' EXIT
g++ -O3 -DNDEBUG -std=c++20 -ffp-contract=off -fno-trapping-math -fno-math-errno -Wno-psabi \
  -Isrc -I"$build/generated" scripts/bench_inference.cpp "$build/libtessera_guidecache.a" -ltbb -o "$bin"
for normals in axis random; do
  for lights in 0 6; do "$bin" "$normals" "$lights"; done
done
