#!/usr/bin/env bash
# Campanile vs OpenCV 5 on the same HDR stacks, in one run:
#   - builds the Rust driver (process/examples/hdr_bench.rs, release);
#   - photographs the synthetic chart through the camera model (7 exposures,
#     8-bit PNG) and times Campanile's calibration and merge on the PNGs;
#   - runs OpenCV's CalibrateDebevec (1000 samples) and MergeDebevec on the
#     same PNGs, measures memory copy bandwidth, and prints the comparison.
# The Python venv lives outside the repository (throwaway).
#
# Usage: bench/hdr/run.sh [WIDTH HEIGHT REPEATS]   (default 1024 768 5)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
width="${1:-1024}"
height="${2:-768}"
repeats="${3:-5}"
out="$(mktemp -d "${TMPDIR:-/tmp}/campanile-hdr-bench.XXXXXX")"
trap 'rm -rf "$out"' EXIT

venv="$("$root/bench/venv.sh" opencv-python-headless numpy)"

(cd "$root" && cargo build --quiet --release -p campanile-process --example hdr_bench)
"$root/target/release/examples/hdr_bench" "$out" "$width" "$height" "$repeats" > "$out/figures.txt"
"$venv/bin/python" "$here/compare_opencv.py" "$out" "$out/figures.txt" "$repeats"
