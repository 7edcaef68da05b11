#!/usr/bin/env bash
# Relighting speed against error (issue 30): the simulated room's scene file
# with its views at 128 x 128 px, 12 of them relit under two new lamps with
# the fixed 256 paths per pixel and to an error target, in one run:
#  1. in the library (session/examples/relight_speed.rs): relight wall and
#     CPU seconds both ways, the first two views' error per 4 x 4 block
#     against a 1024-path reference;
#  2. with CLI=1, end to end through `campanile igi --relight` with and
#     without --error (the recovery included; all 23 photographed views
#     relit), wall, user and system seconds.
#
# Environment: ROUND (paths per pixel a round) and DARK (the dark floor) go
# to the example (its doc).
#
#   bench/relight/run.sh [ERROR,...]      (default 0.03,0.02,0.015)
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
errors="${1:-0.03,0.02,0.015}"
error="${errors%%,*}"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
cd "$repo"
cargo build -q --release -p campanile --bin campanile -p campanile-session --example relight_speed
echo "date $(date -u +%F), load before: $(cut -d' ' -f1-3 /proc/loadavg)"
target/release/examples/relight_speed "$dir/scene" 128 "$errors" 1024 2 1 12
[ "${CLI:-0}" = 1 ] || exit 0
for extra in "" "--error $error"; do
  # shellcheck disable=SC2086
  /usr/bin/time -f "campanile igi --relight $extra: %e s wall, %U user-s, %S sys-s" \
    target/release/campanile -q igi "$dir/scene/scene.ron" --out "$dir/out" \
    --relight "$dir/scene/new-lights.ron" $extra | grep -E '^relit' | tail -3 || true
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
