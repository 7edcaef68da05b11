#!/usr/bin/env bash
# RADIANCE outdoor reference for `campanile outdoor recover` / `outdoor render`
# (issue 31): a building under gendaylit's per-channel sun and sky at five
# times of one day, four viewpoints, rpict with Monte Carlo interreflection.
#
#   validation/outdoor/generate.sh [OUT_DIR]   # bench set, 192x128, default ${TMPDIR:-/tmp}/campanile-validation/outdoor
#   validation/outdoor/generate.sh --fixtures  # rewrites validation/outdoor/fixtures/ (96x64, committed)
#
# Environment: OUTDOOR_AD (rpict -ad, default 512), OUTDOOR_AB (-ab, default 5),
# OUTDOOR_JOBS (parallel rpict runs, default 2), OUTDOOR_BOUNCE (-ab values of the
# bounce study, default 1,2; empty: none). Creates (or reuses) the peer
# venv outside the repository with bench/venv.sh.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
fixtures=0
if [ "${1:-}" = "--fixtures" ]; then
    fixtures=1
    shift
fi
if [ "$#" -gt 1 ] || { [ "$fixtures" = 1 ] && [ "$#" -gt 0 ]; }; then
    echo "usage: validation/outdoor/generate.sh [--fixtures | OUT_DIR]" >&2
    exit 2
fi
venv="$("$repo/bench/venv.sh" pyradiance==1.3.1 numpy)"
opts=(--ad "${OUTDOOR_AD:-512}" --ab "${OUTDOOR_AB:-5}" --jobs "${OUTDOOR_JOBS:-2}" --bounce-study "${OUTDOOR_BOUNCE-1,2}")
if [ "$fixtures" = 1 ]; then
    "$venv/bin/python" "$here/generate.py" --fixtures "$here/fixtures" "${opts[@]}"
else
    out="$(realpath -m "${1:-${TMPDIR:-/tmp}/campanile-validation/outdoor}")"
    case "$out/" in
        "$repo"/*) echo "validation/outdoor/generate.sh: the bench set must live outside the repository ($out)" >&2; exit 2 ;;
    esac
    "$venv/bin/python" "$here/generate.py" "$out" --size 192x128 "${opts[@]}"
fi
"$venv/bin/python" "$here/test_outdoor.py" "$([ "$fixtures" = 1 ] && echo "$here/fixtures" || echo "$out")" > /dev/null
