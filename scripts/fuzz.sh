#!/usr/bin/env bash
# Fuzzes one target, built with clang, libFuzzer, ASan and UBSan in
# build-fuzz/ (tests/fuzz/):
#   scene    the scene loader (tokenizer, parser, loader, PLY and image
#            readers; fuzz_scene_loader.cpp), seeded with the shipped and
#            test scenes;
#   nanovdb  the NanoVDB reader (fuzz_nanovdb_reader.cpp), seeded with
#            tests/fuzz/nvdb_corpus;
#   ply      the PLY reader, whole against chunked (fuzz_ply_reader.cpp),
#            seeded with tests/fuzz/ply_corpus;
#   cli      `tessera render`'s command line and output checks, in-process
#            in a sandbox folder (fuzz_render_cli.cpp), seeded with
#            tests/fuzz/cli_corpus;
#   render   scenes loaded, then rendered at 8x8 on Embree and the portable
#            BVH (fuzz_render_scene.cpp), seeded with tests/fuzz/render_corpus
#            and the shipped and test scenes.
#
#   scripts/fuzz.sh [SECONDS] [JOBS] [scene|nanovdb|ply|cli|render]   (defaults: 600 s, every core, scene)
#
# Each job fuzzes for SECONDS; the corpus grows in out/fuzz/corpus (for the
# other targets: out/fuzz/<target's folder>, e.g. out/fuzz/cli_corpus),
# inputs that crash, hang (over 10 s) or exceed 2 GB land in
# out/fuzz/findings/, named <target>-crash-..., -timeout-..., -oom-... (copy
# them to the matching tests/fuzz/ folder once fixed: the suite replays
# those folders). Logs: out/fuzz/logs/<target>/. The summary gives the
# wall time times the jobs (core-seconds) and the CPU time the fuzzers got,
# which is less where other work shares the cores.
# Exit status 0 when nothing was found, 1 when something was, 2 on setup errors.
set -uo pipefail
cd "$(dirname "$0")/.."
secs=${1:-600}
jobs=${2:-$(nproc)}
target=${3:-scene}
case "$target" in
  scene) exe=fuzz_scene_loader; corpus=corpus; max_len=65536 ;;
  nanovdb) exe=fuzz_nanovdb_reader; corpus=nvdb_corpus; max_len=262144 ;;
  ply) exe=fuzz_ply_reader; corpus=ply_corpus; max_len=65536 ;;
  cli) exe=fuzz_render_cli; corpus=cli_corpus; max_len=4096 ;;
  render) exe=fuzz_render_scene; corpus=render_corpus; max_len=16384 ;;
  *) echo "fuzz.sh: unknown target '$target' (scene, nanovdb, ply, cli or render)" >&2; exit 2 ;;
esac
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 2; }
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fsanitize=fuzzer-no-link -fno-omit-frame-pointer"
cmake -S . -B build-fuzz -DTESSERA_FUZZ=ON -DTESSERA_CUDA=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_CXX_FLAGS="$flags" >build-fuzz.log 2>&1 || { cat build-fuzz.log >&2; exit 2; }
cmake --build build-fuzz --target "$exe" -j"$jobs" >>build-fuzz.log 2>&1 || { tail -30 build-fuzz.log >&2; exit 2; }
logs=out/fuzz/logs/$target  # one folder per target: two targets may run at once
mkdir -p out/fuzz/"$corpus" out/fuzz/findings "$logs"
if [ "$target" = scene ] || [ "$target" = render ]; then cp -n scenes/*.pbrt tests/data/*.pbrt out/fuzz/"$corpus"/ 2>/dev/null; fi
cp -n tests/fuzz/"$corpus"/* out/fuzz/"$corpus"/ 2>/dev/null
findings() { ls out/fuzz/findings | grep -c "^$target-"; }
# CPU seconds used by this script's children (the second line of bash's
# `times`, which must run in this shell: a $(...) subshell has its own):
# the fuzzer's share, where other work competes for the cores.
times_seconds() { awk 'NR == 2 { split($1, u, /[ms]/); split($2, s, /[ms]/); printf "%d", u[1] * 60 + u[2] + s[1] * 60 + s[2] }' "$logs/times"; }
before=$(findings)
times >"$logs/times"
cpu_before=$(times_seconds)
start=$(date +%s)
rm -f "$logs"/fuzz-*.log
# Absolute paths: the cli target runs its commands in a sandbox folder of
# its own, where a crash would otherwise leave its input. The tessera
# commands' own output is discarded (-close_fd_mask=3; libFuzzer's and the
# sanitizers' reports still reach the log).
quiet=""
if [ "$target" = cli ] || [ "$target" = render ]; then quiet="-close_fd_mask=3"; fi
(cd "$logs" && ASAN_OPTIONS=detect_leaks=0 "$PWD"/../../../../build-fuzz/"$exe" "$PWD/../../$corpus" -max_total_time="$secs" \
  -jobs="$jobs" -workers="$jobs" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" $quiet \
  -artifact_prefix="$PWD/../../findings/$target-" >/dev/null 2>&1)
end=$(date +%s)
times >"$logs/times"
cpu=$(( $(times_seconds) - cpu_before ))
after=$(findings)
execs=$(grep -h "DONE" "$logs"/fuzz-*.log 2>/dev/null | sed -n 's/^#\([0-9]*\).*/\1/p' | awk '{s+=$1} END {print s+0}')
echo "fuzz.sh: $jobs jobs x ${secs} s ($(( (end - start) * jobs )) core-seconds, $cpu CPU-seconds used), $execs inputs run," \
     "corpus $(ls out/fuzz/"$corpus" | wc -l) files, $((after - before)) new findings in out/fuzz/findings/$target-*"
grep -h "ERROR: \|runtime error:" "$logs"/fuzz-*.log 2>/dev/null | sort | uniq -c | head -20
[ "$after" -eq "$before" ]
