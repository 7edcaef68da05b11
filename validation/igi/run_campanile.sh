#!/usr/bin/env bash
# Runs `campanile igi` on every reference room under DIR and compares with
# its truth.
#
#   validation/igi/run_campanile.sh DIR [CAMPANILE] [-- extra campanile igi options]
#
# DIR holds <room>-<mode>/ directories (the fixtures or a bench set).
# CAMPANILE defaults to /tmp/campanile-bins/campanile. Each room's scene.ron
# is used, or scene-exr.ron with IGI_LEGACY=1 (binaries without the
# RGBE/view-string/RadianceLight fields). Results go to
# ${TMPDIR:-/tmp}/campanile-validation/igi-out/<room>-<mode>/; compare.py's
# table is printed; the exit status is 1 if any room fails its bounds.
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
dir="${1:?usage: run_campanile.sh DIR [CAMPANILE] [-- options]}"
shift
bin="/tmp/campanile-bins/campanile"
if [ "$#" -gt 0 ] && [ "$1" != "--" ]; then bin="$1"; shift; fi
[ "${1:-}" = "--" ] && shift
venv="$("$repo/bench/venv.sh" numpy OpenEXR)"
outs="${TMPDIR:-/tmp}/campanile-validation/igi-out"
mkdir -p "$outs"
scene_name="scene.ron"
[ "${IGI_LEGACY:-0}" = 1 ] && scene_name="scene-exr.ron"
status=0
for d in "$dir"/*/; do
    [ -f "$d/truth.json" ] || continue
    name="$(basename "$d")"
    out="$outs/$name"
    rm -rf "$out"
    echo "== $name: $bin igi $d$scene_name --out $out $*"
    start=$(date +%s.%N)
    "$bin" igi "$d$scene_name" --out "$out" "$@" > "$out.log" 2>&1
    rc=$?
    echo "   exit $rc, $(echo "$(date +%s.%N) - $start" | bc) s (log $out.log)"
    "$venv/bin/python" "$here/compare.py" "$out" "$d/truth.json" --json "$out.compare.json" || status=1
done
exit $status
