#!/usr/bin/env bash
# Creates (once) and prints the path of a throwaway Python venv OUTSIDE the
# repository, for the peer tools benchmarks compare against (OpenCV, pvlib,
# scipy). Nothing from it is committed.
#
#   venv=$(bench/venv.sh opencv-python-headless numpy)   # then "$venv/bin/python" ...
#
# The location can be set with CAMPANILE_BENCH_VENV.
set -euo pipefail
venv="${CAMPANILE_BENCH_VENV:-${TMPDIR:-/tmp}/campanile-bench-venv}"
repo="$(cd "$(dirname "$0")/.." && pwd)"
case "$venv/" in
    "$repo"/*) echo "bench/venv.sh: the venv must live outside the repository ($venv)" >&2; exit 2 ;;
esac
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv" >&2
    "$venv/bin/pip" install -q --upgrade pip >&2
fi
if [ "$#" -gt 0 ]; then
    "$venv/bin/pip" install -q "$@" >&2
fi
echo "$venv"
