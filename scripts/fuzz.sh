#!/usr/bin/env bash
# Fuzzes the scene loader (tokenizer, parser, loader, PLY and image readers;
# tests/fuzz/fuzz_scene_loader.cpp, seeded with the shipped and test scenes),
# the NanoVDB reader (tests/fuzz/fuzz_nanovdb_reader.cpp, seeded with
# tests/fuzz/nvdb_corpus) or the PLY reader, whole against chunked
# (tests/fuzz/fuzz_ply_reader.cpp, seeded with tests/fuzz/ply_corpus): builds
# the target with clang, libFuzzer, ASan and UBSan in build-fuzz/ and runs it.
#
#   scripts/fuzz.sh [SECONDS] [JOBS] [scene|nanovdb|ply]   (defaults: 600 s, every core, scene)
#
# Each job fuzzes for SECONDS; the corpus grows in out/fuzz/corpus (for
# nanovdb: out/fuzz/nvdb_corpus, for ply: out/fuzz/ply_corpus), inputs that
# crash, hang (over 10 s) or exceed 2 GB land in out/fuzz/findings/ (copy
# them to the matching tests/fuzz/ folder once fixed: the suite replays
# those folders).
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
  *) echo "fuzz.sh: unknown target '$target' (scene, nanovdb or ply)" >&2; exit 2 ;;
esac
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 2; }
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fsanitize=fuzzer-no-link -fno-omit-frame-pointer"
cmake -S . -B build-fuzz -DTESSERA_FUZZ=ON -DTESSERA_CUDA=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_CXX_FLAGS="$flags" >build-fuzz.log 2>&1 || { cat build-fuzz.log >&2; exit 2; }
cmake --build build-fuzz --target "$exe" -j"$jobs" >>build-fuzz.log 2>&1 || { tail -30 build-fuzz.log >&2; exit 2; }
mkdir -p out/fuzz/"$corpus" out/fuzz/findings out/fuzz/logs
if [ "$target" = scene ]; then cp -n scenes/*.pbrt tests/data/*.pbrt out/fuzz/corpus/ 2>/dev/null; fi
cp -n tests/fuzz/"$corpus"/* out/fuzz/"$corpus"/ 2>/dev/null
before=$(ls out/fuzz/findings | wc -l)
start=$(date +%s)
rm -f out/fuzz/logs/fuzz-*.log
(cd out/fuzz/logs && ASAN_OPTIONS=detect_leaks=0 ../../../build-fuzz/"$exe" ../"$corpus" -max_total_time="$secs" \
  -jobs="$jobs" -workers="$jobs" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" \
  -artifact_prefix=../findings/ >/dev/null 2>&1)
end=$(date +%s)
after=$(ls out/fuzz/findings | wc -l)
execs=$(grep -h "DONE" out/fuzz/logs/fuzz-*.log 2>/dev/null | sed -n 's/^#\([0-9]*\).*/\1/p' | awk '{s+=$1} END {print s+0}')
echo "fuzz.sh: $jobs jobs x ${secs} s ($(( (end - start) * jobs )) CPU-seconds), $execs inputs run," \
     "corpus $(ls out/fuzz/"$corpus" | wc -l) files, $((after - before)) new findings in out/fuzz/findings/"
grep -h "ERROR: \|runtime error:" out/fuzz/logs/fuzz-*.log 2>/dev/null | sort | uniq -c | head -20
[ "$after" -eq "$before" ]
