#!/usr/bin/env bash
# Independent sky references for `campanile sky fit` (issue 22): gendaylit
# skies rendered by rtrace, and the 15 CIE standard general skies.
#
#   validation/sky/generate.sh [OUT_DIR]   # full set, default ${TMPDIR:-/tmp}/campanile-validation/sky
#   validation/sky/generate.sh --fixtures  # rewrites validation/sky/fixtures/ (committed)
#
# Creates (or reuses) the peer venv outside the repository with
# bench/venv.sh, generates, then runs the generator's own tests on the output.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
fixtures=0
if [ "${1:-}" = "--fixtures" ]; then
    fixtures=1
    shift
fi
if [ "$#" -gt 1 ]; then
    echo "usage: validation/sky/generate.sh [--fixtures | OUT_DIR]" >&2
    exit 2
fi
venv="$("$repo/bench/venv.sh" pyradiance==1.3.1 numpy scipy pvlib)"
if [ "$fixtures" = 1 ]; then
    if [ "$#" -gt 0 ]; then
        echo "validation/sky/generate.sh: --fixtures writes validation/sky/fixtures/ and takes no directory" >&2
        exit 2
    fi
    out="$here/fixtures"
    mkdir -p "$out"
    "$venv/bin/python" "$here/generate.py" --fixtures "$out"
else
    out="${1:-${TMPDIR:-/tmp}/campanile-validation/sky}"
    out="$(realpath -m "$out")"
    case "$out/" in
        "$repo"/*) echo "validation/sky/generate.sh: the full set must live outside the repository ($out)" >&2; exit 2 ;;
    esac
    mkdir -p "$out"
    "$venv/bin/python" "$here/generate.py" "$out"
fi
"$venv/bin/python" "$here/test_generate.py" "$out"
