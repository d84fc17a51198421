#!/usr/bin/env bash
# Installs the Debian packages Tessera builds and runs with. Idempotent: it only
# calls apt-get (and apt-get update) when a package is actually missing.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  libembree-dev embree-tools      # ray tracing kernels; embree-tools = reference path tracer for benchmarks
  libopenexr-dev                  # EXR output and input
  libglm-dev                      # vector math shared by CPU and CUDA
  libcereal-dev                   # serialisation
  libopenmpi-dev openmpi-bin      # the render farm
  libtbb-dev                      # CPU parallelism
  libgtest-dev                    # tests
  libcli11-dev                    # command line
  nlohmann-json3-dev              # stats and compare JSON
  zlib1g-dev                      # .ply.gz meshes
  libopenimageio-dev              # texture and environment images (EXR, PFM, PNG, TGA, HDR...)
  libstb-dev                      # PNG/JPEG read, PNG write
  libnanovdb-dev                  # "nanovdb" media (.nvdb volumes; brings libblosc-dev)
  python3                         # benchmark and test helper scripts
  python3-matplotlib              # benchmark plots (scripts/bench_*.py)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
