#!/usr/bin/env bash
# Sky fit against scipy on skies Campanile did not make (issue 22): the
# references of validation/sky (RADIANCE gendaylit skies rendered by rtrace,
# CIE standard skies), full set (~2060 samples a sky) made by
# validation/sky/generate.sh if absent. In the same run, on the same
# samples, from the same start (the one Campanile's fit chose):
# Campanile's whole fit (starts, every candidate, the model choice),
# Campanile's Levenberg-Marquardt of the Perez form alone, and
# scipy.optimize.least_squares(method="lm") of the Perez form alone; and
# Campanile's fit of each sky's three channels, one after another and with
# rayon side by side (the machine's load and core count are printed: the
# timings are only comparable within one run).
# Usage: bench/sky/run.sh [REFERENCE_DIR [KEEP_DIR]] (KEEP_DIR: where to
# keep the CSVs compared, else a temporary directory removed at the end)
set -euo pipefail
cd "$(dirname "$0")/../.."
refs="${1:-${TMPDIR:-/tmp}/campanile-validation/sky}"
[ -f "$refs/manifest.csv" ] || validation/sky/generate.sh "$refs"
venv="$(bench/venv.sh scipy numpy)"
cargo build --release -q -p campanile-process --example sky_references_bench
if [ -n "${2:-}" ]; then
    work="$2"
    mkdir -p "$work"
else
    work="$(mktemp -d)"
    trap 'rm -rf "$work"' EXIT
fi
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
target/release/examples/sky_references_bench "$refs" "$work"
"$venv/bin/python" validation/sky/scipy_fit.py "$refs" --start "$work/start.csv" --noise 0.02 --seed 7 --reps 5 --out "$work/scipy.csv" > /dev/null
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "cores: $(nproc)"
"$venv/bin/python" bench/sky/compare.py "$work/campanile.csv" "$work/scipy.csv" "$work/three.csv"
