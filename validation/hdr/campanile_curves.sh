#!/usr/bin/env bash
# Campanile's response curves on the real sets, on the same files and
# exposures as peers.py: `campanile hdr calibrate` (Debevec–Malik, defaults;
# and Robertson) with --times from each set's times.txt.
#
# Until the EXIF reader lands, the times come from exiftool (fetch_sets.sh)
# and `--allow-resampled` is passed: the resampling check refuses these
# camera files (see resampled.md).
#
#   validation/hdr/campanile_curves.sh [SET...]
# BIN (default target/release/campanile) is the binary to run.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
bin="${BIN:-$root/target/release/campanile}"
sets="${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for d in "$sets"/*/; do [ -f "$d/times.txt" ] && names+=("$(basename "$d")"); done
fi
for name in "${names[@]}"; do
  d="$sets/$name"
  files=(); times=()
  while read -r f t; do files+=("$d/$f"); times+=("$t"); done < "$d/times.txt"
  tlist="$(IFS=,; echo "${times[*]}")"
  for method in debevec robertson; do
    start=$(date +%s.%N)
    rc=0
    "$bin" hdr calibrate "${files[@]}" --times "$tlist" --method "$method" --allow-resampled \
      -o "$d/campanile_$method.csv" --plot "$d/campanile_$method.svg" > "$d/campanile_$method.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || { echo "$name $method: exit $rc: $(tail -1 "$d/campanile_$method.log")"; continue; }
    end=$(date +%s.%N)
    printf '%s %s %.2f s\n' "$name" "$method" "$(echo "$end - $start" | bc)"
  done
done
