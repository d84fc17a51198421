#!/usr/bin/env bash
# Configures and builds Tessera (Release) into build/. Idempotent.
#   scripts/build.sh            everything: the binary, the tests, the tools
#   scripts/build.sh tessera    only the named targets (the quick start's render needs only `tessera`)
# TESSERA_CUDA=ON|OFF: the CUDA backend (default ON where nvcc is found).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
CUDA=${TESSERA_CUDA:-ON}
if [ "$CUDA" = ON ] && { [ -x /usr/local/cuda/bin/nvcc ] || command -v nvcc >/dev/null; }; then
  echo "build: nvcc found: the CUDA backend's kernels are compiled too; ptxas takes minutes for each of them" \
       "(TESSERA_CUDA=OFF skips them; the CPU backends need nothing from nvcc)"
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTESSERA_CUDA="$CUDA" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build -j "$JOBS" "${targets[@]}"
