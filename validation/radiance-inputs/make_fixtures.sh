#!/usr/bin/env bash
# Rewrites validation/radiance-inputs/fixtures/ (committed) with RADIANCE
# (pyradiance) and OpenCV; see make_fixtures.py. The venv lives outside the
# repository (bench/venv.sh).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
venv="$("$repo/bench/venv.sh" pyradiance==1.3.1 numpy opencv-python-headless)"
"$venv/bin/python" "$here/make_fixtures.py" "$here/fixtures"
