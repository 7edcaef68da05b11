#!/usr/bin/env bash
# Camera pose from targets, speed against the thesis and OpenCV (BENCHMARKS.md,
# "Camera pose from targets"): Campanile's AprilTag detection and registration
# on synthetic walls of 50 and 100 tags, then OpenCV (aruco AprilTag 36h11
# detection, solvePnP, solvePnPRansac) on the same photos and correspondences.
#
#   bench/registration/run.sh [DIR]
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
dir="${1:-${TMPDIR:-/tmp}/campanile-registration-bench}"
cd "$repo"
uptime
cargo bench -q -p campanile-process --bench registration -- "$dir"
venv=$(bench/venv.sh opencv-python-headless numpy)
"$venv/bin/python" bench/registration/opencv.py "$dir"
uptime
