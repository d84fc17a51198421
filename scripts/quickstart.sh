#!/usr/bin/env bash
# Quick start: install what is missing, build the renderer alone, render the
# built-in Cornell box. The CUDA backend is built only where a GPU is visible:
# the first render does not wait for ptxas on a machine that cannot run it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
if [ -z "${TESSERA_CUDA:-}" ]; then
  if command -v nvidia-smi >/dev/null && nvidia-smi -L >/dev/null 2>&1; then export TESSERA_CUDA=ON; else export TESSERA_CUDA=OFF; fi
fi
scripts/build.sh tessera
mkdir -p out
./build/tessera render -o out/cornell-box.exr --stats out/cornell-box.json
