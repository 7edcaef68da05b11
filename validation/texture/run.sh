#!/usr/bin/env bash
# Independent check of `campanile texture`: the simulator's photographs of the
# floodlit tower are textured by Campanile, then Mitsuba 3 renders the textured
# OBJ from a check view and the render is compared with the simulator's.
# Nothing is committed: the fixture is regenerated (deterministic seeds).
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
work="${1:-${TMPDIR:-/tmp}/campanile-texture-check}"
venv=$("$repo/bench/venv.sh" mitsuba numpy)
cd "$repo"
cargo run -q -p campanile-sim --example texture_fixture -- "$work/fixture"
cargo run -q -- texture examples/campanile-scene.ron --poses "$work/fixture/poses.ron" \
    --station examples/sim-station.ron --photos "$work/fixture/photos" --texel 0.125 \
    --surface south-face --surface east-face --surface north-face --surface west-face \
    --surface pillars --surface roof --out "$work/textured"
"$venv/bin/python" validation/texture/mitsuba_view.py "$work/textured" "$work/fixture"
