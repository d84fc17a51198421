#!/usr/bin/env bash
# Quick start: install what is missing, build, render the built-in Cornell box.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
mkdir -p out
./build/tessera render -o out/cornell-box.exr --stats out/cornell-box.json
