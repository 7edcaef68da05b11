#!/usr/bin/env bash
# Segmentation peers (issue 28): Open3D's plane segmentation (iterated RANSAC
# `segment_plane` + `cluster_dbscan`, and `detect_planar_patches`) and
# Campanile's normalized-cut segmenter (`campanile segment`, release build) on
# the simulated room's and tower's merged scans, scored by one code
# (open3d_segment.py's metrics, defined in bench/segment/README.md) against
# the scanner's true surfaces. Prints a markdown table. Open3D runs in the
# throwaway venv of bench/venv.sh (outside the repository).
#
#   bench/segment/run.sh                          # 5 scans each of 720 × 1440 beams (0.25° in azimuth)
#   bench/segment/run.sh 1000 2000 room           # the scale anchor: ~10⁷ room points
#   bench/segment/run.sh 720 1440 room campanile  # Campanile's row alone
#
# Arguments: ROWS COLUMNS (default 720 1440), the sets (default
# room,building) and the tools (default open3d,campanile). The scans are
# written to a temporary directory, or to $CAMPANILE_SEGMENT_SCANS when set
# (kept then, with Campanile's output in campanile-SET/ beside them).
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
rows="${1:-720}"
columns="${2:-1440}"
sets="${3:-room,building}"
tools="${4:-open3d,campanile}"
for tool in ${tools//,/ }; do
    case "$tool" in
        open3d|campanile) ;;
        *) echo "run.sh: tool $tool in \"$tools\": expected open3d, campanile or both (comma-separated)" >&2; exit 2 ;;
    esac
done
venv="$("$repo/bench/venv.sh" open3d numpy scipy)"
if [ -n "${CAMPANILE_SEGMENT_SCANS:-}" ]; then
    scans="$CAMPANILE_SEGMENT_SCANS"
else
    scans="$(mktemp -d)"
    trap 'rm -rf "$scans"' EXIT
fi
# The scanner only makes the input (its speed is in BENCHMARKS.md, "Range
# scans"): the dev profile, whose dependencies are at opt-level 3, is enough.
(cd "$repo" && cargo build -q -p campanile-sim --example range_scans)
if [[ ",$tools," == *,campanile,* ]]; then
    (cd "$repo" && cargo build -q --release --bin campanile)
fi
if [ ! -f "$scans/room.truth.json" ] || [ "$(cat "$scans/grid" 2>/dev/null)" != "$rows $columns" ]; then
    "$repo/target/debug/examples/range_scans" "$scans" --rows "$rows" --columns "$columns" --truth | grep -E '^(room|building):|verdict' >&2
    echo "$rows $columns" > "$scans/grid"
fi
echo "# $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GB", $2 / 1048576}' /proc/meminfo); $(date -u +%Y-%m-%d)" >&2
header=--header
for set in ${sets//,/ }; do
    if [[ ",$tools," == *,open3d,* ]]; then
        "$venv/bin/python" "$repo/bench/segment/open3d_segment.py" "$scans" "$set" --check-metrics $header
        header=
    fi
    if [[ ",$tools," == *,campanile,* ]]; then
        keep=()
        if [ -n "${CAMPANILE_SEGMENT_SCANS:-}" ]; then
            keep=(--out "$scans/campanile-$set")
            mkdir -p "$scans/campanile-$set"
        fi
        "$venv/bin/python" "$repo/bench/segment/campanile_segment.py" "$scans" "$set" \
            --campanile "$repo/target/release/campanile" "${keep[@]}" $header
        header=
    fi
done
