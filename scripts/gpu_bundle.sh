#!/usr/bin/env bash
# Prepares, on a machine with the full build and nvcc, what a bare GPU
# machine needs to check the CUDA backend: the device check program (linked
# without the renderer's libraries but oneTBB's; CUDA's runtime is static) and the
# fixtures it reads (packed scenes and their host-emulated images).
# Usage: [SPP=64] [RES=128x96] scripts/gpu_bundle.sh [BUNDLE_DIR] (default .gpu/bundle); then, on
# the GPU machine (with .gpu carried there):
#   GLM_INCLUDE=.gpu/include GPU_BUNDLE=.gpu/bundle scripts/gpu_check.sh OUT_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
bundle=${1:-.gpu/bundle}
cmake --build build -j "$(nproc)" --target device_backend_on_device make_gpu_fixtures
mkdir -p "$bundle/fixtures"
cp build/device_backend_on_device "$bundle/"
# Its one shared library a bare GPU machine lacks: oneTBB (the network trains on the host).
tbb=$(ldd build/device_backend_on_device | awk '/libtbb\.so/ && $3 ~ /^\// {print $3; exit}')
[ -n "$tbb" ] || { echo "gpu_bundle: device_backend_on_device links no libtbb found by ldd" >&2; exit 1; }
cp -L "$tbb" "$bundle/"
build/make_gpu_fixtures "$bundle/fixtures" "${SPP:-64}" "${RES:-128x96}"
# GLM for the checks gpu_check.sh builds there with nvcc (a bare GPU machine has none).
mkdir -p .gpu/include && cp -r /usr/include/glm .gpu/include/
du -sh "$bundle" .gpu/include
