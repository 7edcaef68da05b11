#!/usr/bin/env bash
# Solar position against pvlib, same grid, same run: the library
# (`sun_positions`) and the CLI (`campanile sun --csv`), each against pvlib.
# Prints two Markdown rows for BENCHMARKS.md.
#   Usage: bench/sun/run.sh [INSTANTS] [SITES_PER_INSTANT]
# SITES_PER_INSTANT=1 makes every row its own instant (no sharing of the
# time-dependent terms); the default grid shares them across 50 sites.
set -euo pipefail
cd "$(dirname "$0")/../.."
m="${1:-200}"
s="${2:-50}"
venv="$(bench/venv.sh pvlib numpy)"
cargo build --release -q -p campanile-process --example sun_throughput
cargo build --release -q -p campanile --bin campanile
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$venv/bin/python" bench/sun/compare.py "$m" "$s" "$work" target/release/examples/sun_throughput target/release/campanile
