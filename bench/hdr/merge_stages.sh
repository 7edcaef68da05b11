#!/usr/bin/env bash
# The HDR merge against the memory roofline, and `campanile hdr merge`'s
# stages, in one run on one bracket:
#   - hdr_bench photographs the synthetic chart (7 exposures, 8-bit PNG),
#     times the in-memory merge, and measures in the same process the copy
#     bandwidth and a kernel that moves the merge's bytes with no table
#     lookups (the roofline figures: merge_share_of_copy_roofline, ...);
#   - merge_stages times decoding alone, the streamed merge (decoding on its
#     own thread), the in-memory merge and the OpenEXR encode;
#   - the CLI merges the same files (best of REPEATS, wall seconds).
# No peer tool is needed. BIN_DIR=DIR runs binaries already built there
# (DIR/examples/hdr_bench, DIR/examples/merge_stages, DIR/campanile), for
# before/after comparisons.
#
# Usage: bench/hdr/merge_stages.sh [WIDTH HEIGHT REPEATS]   (default 4000 3000 3: 12 MP)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
width="${1:-4000}"
height="${2:-3000}"
repeats="${3:-3}"
out="$(mktemp -d "${TMPDIR:-/tmp}/campanile-merge-stages.XXXXXX")"
trap 'rm -rf "$out"' EXIT

bin="${BIN_DIR:-}"
if [ -z "$bin" ]; then
    (cd "$root" && cargo build --quiet --release -p campanile-process --example hdr_bench --example merge_stages \
        && cargo build --quiet --release --bin campanile)
    bin="$root/target/release"
fi
echo "load average at the start: $(cut -d' ' -f1-3 /proc/loadavg) ($(nproc) cores)"
"$bin/examples/hdr_bench" "$out" "$width" "$height" "$repeats" \
    | grep -E '^(width|height|exposures|threads|campanile_merge_best|campanile_merge_mpx|memory_|merge_|same_traffic)'
"$bin/examples/merge_stages" "$out" "$repeats"
times="$(paste -sd, "$out/times.txt")"
TIMEFORMAT=%R
for _ in $(seq "$repeats"); do
    { time "$bin/campanile" -q hdr merge "$out"/exposure_*.png --times "$times" \
        --curve "$out/campanile_curve.csv" -o "$out/cli.exr" > /dev/null; } 2>> "$out/cli_times.txt"
done
awk 'NR == 1 || $1 < b { b = $1 } END { printf "cli_hdr_merge_wall_s=%.3f\n", b }' "$out/cli_times.txt"
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
