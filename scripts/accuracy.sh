#!/usr/bin/env bash
# One command: installs what is missing, builds, and regenerates
# docs/accuracy.md and docs/accuracy/ (references are cached in
# out/references/). Arguments go to scripts/accuracy.py (see --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
# Debian's python3 has the python3-matplotlib the install step added; a
# python3 earlier on PATH (pyenv, venv) may not.
PYTHON=python3
if [ -x /usr/bin/python3 ]; then PYTHON=/usr/bin/python3; fi
exec "$PYTHON" scripts/accuracy.py "$@"
