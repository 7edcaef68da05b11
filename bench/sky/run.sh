#!/usr/bin/env bash
# Sky fit: speed against error over sampling density, then the same fit in
# scipy.optimize.least_squares on the same samples, in the same run.
# Usage: bench/sky/run.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
venv="$(bench/venv.sh scipy numpy)"
cargo build --release -q -p campanile-process --example sky_fit_bench
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
target/release/examples/sky_fit_bench "$work"
echo
"$venv/bin/python" bench/sky/compare.py "$work"
