#!/usr/bin/env bash
# Regenerates the committed fixtures of validation/hdr/fixtures/ from the full
# sets that fetch_sets.sh extracted:
#   - radiantlab-eos/: a 640×640 crop of every frame of the Canon EOS 5D Mark II
#     bracket (window frame, sky, trees, wall), cut with `jpegtran -copy all
#     -crop` on MCU boundaries: the camera's own DCT coefficients and its EXIF,
#     no decode/re-encode and no resampling; plus exposures.csv and the
#     hdrgen response curve the set ships (Response_function.rsp).
#   - <phone set>/exposures.csv only (EXIF facts; the pictures carry no licence).
# Needs jpegtran (Debian: libjpeg-turbo-progs) and exiftool.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
sets="${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}"
fx="$here/fixtures"

crop="640x640+3904+1344"
mkdir -p "$fx/radiantlab-eos"
for f in "$sets"/radiantlab-eos/IMG_*.JPG; do
  jpegtran -copy all -crop "$crop" "$f" > "$fx/radiantlab-eos/$(basename "$f")"
done
cp "$sets/radiantlab-eos/exposures.csv" "$sets/radiantlab-eos/Response_function.rsp" "$fx/radiantlab-eos/"
echo "$crop" > "$fx/radiantlab-eos/crop.txt"

for s in cwz-library1 cwz-library3 cwz-building1; do
  mkdir -p "$fx/$s"
  cp "$sets/$s/exposures.csv" "$fx/$s/"
done
du -sh "$fx"/* >&2

# The committed crops as a set of their own, so that peers.py and
# campanile_curves.sh can compute the curves committed in
# fixtures/radiantlab-eos/curves/ (copy_curves below).
mkdir -p "$sets/radiantlab-eos-crop"
cp "$fx"/radiantlab-eos/IMG_*.JPG "$sets/radiantlab-eos/times.txt" "$sets/radiantlab-eos/Response_function.rsp" "$sets/radiantlab-eos-crop/"
