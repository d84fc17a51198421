#!/usr/bin/env bash
# CTest's cuda.device_backend_on_device: skips (77) without a device; else
# writes the fixtures and runs the GPU check on them.
# Usage: device_backend_check.sh CHECK_BINARY FIXTURE_MAKER FIXTURE_DIR
set -u
"$1" --probe
rc=$?
[ "$rc" -eq 77 ] && exit 77
[ "$rc" -ne 0 ] && exit "$rc"
"$2" "$3" && "$1" "$3"/*.fixture
