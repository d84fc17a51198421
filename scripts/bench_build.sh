#!/usr/bin/env bash
# Build and test times of the committed HEAD on this machine, each from a
# fresh clone in a temporary folder (a benchmark, not a test):
#   cpu_build     clean build of everything with TESSERA_CUDA=OFF
#   touch_stage   rebuild of the binary after touching one integrator stage
#   suite         ctest -j$(nproc) in that build
#   quickstart    scripts/quickstart.sh from a fresh clone (build the binary, render)
#   nvcc_build    clean build of everything with the CUDA backend (where nvcc is)
#   ci            .ci/run from a fresh clone (install, build, suite)
# Usage: scripts/bench_build.sh [STEP...]   (default: all of them, in that order)
# Prints one line per step ("step seconds status") and writes them to
# out/bench-build.txt. The machine should be otherwise idle: compile times
# on 2 cores double under load.
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
STEPS=("$@")
[ ${#STEPS[@]} -gt 0 ] || STEPS=(cpu_build touch_stage suite quickstart nvcc_build ci)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
TMP=$(mktemp -d /tmp/tessera-bench-build.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
mkdir -p out
RESULTS=out/bench-build.txt
echo "# scripts/bench_build.sh at $(git rev-parse --short HEAD), $(nproc) cores, $(date -u +%FT%TZ)" >"$RESULTS"

fresh_clone() {  # $1: folder name under $TMP
  rm -rf "${TMP:?}/$1"
  git clone -q "$ROOT" "$TMP/$1"
}

timed() {  # $1: step name; the rest: the command, run in the current folder
  local name=$1
  shift
  local t0 t1 status=ok
  t0=$(date +%s.%N)
  "$@" >"$TMP/$name.log" 2>&1 || status="FAILED (log: kept in out/bench-build-$name.log)"
  t1=$(date +%s.%N)
  [ "$status" = ok ] || cp "$TMP/$name.log" "out/bench-build-$name.log"
  printf '%-12s %7.0f s  %s\n' "$name" "$(awk "BEGIN { print $t1 - $t0 }")" "$status" | tee -a "$ROOT/$RESULTS"
}

for step in "${STEPS[@]}"; do
  case $step in
    cpu_build)
      fresh_clone cpu
      (cd "$TMP/cpu" && timed cpu_build env TESSERA_CUDA=OFF scripts/build.sh)
      ;;
    touch_stage)
      [ -d "$TMP/cpu/build" ] || { fresh_clone cpu; (cd "$TMP/cpu" && TESSERA_CUDA=OFF scripts/build.sh >/dev/null); }
      (cd "$TMP/cpu" && touch src/integrator/integrator_scatter.h && timed touch_stage cmake --build build -j "$(nproc)" --target tessera)
      ;;
    suite)
      [ -d "$TMP/cpu/build" ] || { fresh_clone cpu; (cd "$TMP/cpu" && TESSERA_CUDA=OFF scripts/build.sh >/dev/null); }
      (cd "$TMP/cpu/build" && timed suite ctest -j "$(nproc)" --timeout 600)
      ;;
    quickstart)
      fresh_clone quick
      (cd "$TMP/quick" && timed quickstart scripts/quickstart.sh)
      ;;
    nvcc_build)
      if [ -x /usr/local/cuda/bin/nvcc ] || command -v nvcc >/dev/null; then
        fresh_clone nvcc
        (cd "$TMP/nvcc" && timed nvcc_build env TESSERA_CUDA=ON scripts/build.sh)
      else
        echo "nvcc_build   skipped: no nvcc" | tee -a "$RESULTS"
      fi
      ;;
    ci)
      fresh_clone ci
      (cd "$TMP/ci" && timed ci .ci/run)
      ;;
    *) echo "bench_build: unknown step $step" >&2; exit 2 ;;
  esac
done
