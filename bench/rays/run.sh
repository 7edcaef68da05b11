#!/usr/bin/env bash
# Ray casting, Campanile against Mitsuba 3 (Embree) on the same triangles and
# the same rays, in one run. The peer runs in the throwaway venv of
# bench/venv.sh (outside the repository). Debian bookworm needs `libllvm19`
# for Dr.Jit's LLVM backend.
#
#   bench/rays/run.sh
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
venv="$("$repo/bench/venv.sh" mitsuba numpy)"
dump="$(mktemp -d)"
trap 'rm -rf "$dump"' EXIT
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
(cd "$repo" && CAMPANILE_RAYS_DUMP="$dump" cargo bench -q -p campanile-sim --bench rays)
"$venv/bin/python" "$repo/bench/rays/peer.py" "$dump"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
