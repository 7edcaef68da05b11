#!/usr/bin/env bash
# Extracts the real bracket sets used by validation/hdr/ from local git
# snapshots of their public repositories, into
# ${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}/<set>/,
# and writes per set `exposures.csv` (what exiftool reports) and `times.txt`
# (relative exposure per file, t·ISO/(100·N²)·N0², the N0 of the set's first
# file, so that brackets varying ISO or aperture are described by one number).
#
# The snapshots are bare git directories (no work tree), e.g. what a
# `git clone --mirror` of the repository gives; point MIRRORS at the folder
# that holds them as OWNER+NAME/repo. Nothing is downloaded here.
#
#   validation/hdr/fetch_sets.sh            # all sets
#   MIRRORS=/path/to/mirrors validation/hdr/fetch_sets.sh
#
# Needs git and exiftool (Debian: libimage-exiftool-perl).
set -euo pipefail
mirrors="${MIRRORS:-/work/.mirror}"
out="${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}"

# set | repository | commit | folder in the repository | file pattern
sets=(
  "radiantlab-eos|radiantlab/HDRICalibrationTool|81cc27b3c652acd5f7d6cc3c6ec777558208e2da|example/JPEG|\.JPG$"
  "cwz-library1|C-W-Z/hdr-imaging|8a0dc4e8be90ea1542bfe550c4df53d51f4316e7|data/library1/origin|\.JPG$"
  "cwz-library3|C-W-Z/hdr-imaging|8a0dc4e8be90ea1542bfe550c4df53d51f4316e7|data/library3/origin|\.JPG$"
  "cwz-building1|C-W-Z/hdr-imaging|8a0dc4e8be90ea1542bfe550c4df53d51f4316e7|data/building1/origin|\.JPG$"
  "memorial|venson-chiang/Halide_ToneMapping|af2da903840f092f1cb5c5267a71b56cc5c39579|images|^memorial00[67][0-9]\.png$"
)

for s in "${sets[@]}"; do
  IFS='|' read -r name repo commit folder pattern <<<"$s"
  git_dir="$mirrors/${repo/\//+}/repo"
  if [ ! -d "$git_dir" ]; then
    echo "fetch_sets.sh: no snapshot of $repo at $git_dir (skipping $name)" >&2
    continue
  fi
  dest="$out/$name"
  mkdir -p "$dest"
  n=0
  while read -r path; do
    base="$(basename "$path")"
    [[ "$base" =~ $pattern ]] || continue
    git -C "$git_dir" show "$commit:$path" > "$dest/$base"
    n=$((n + 1))
  done < <(git -C "$git_dir" ls-tree --name-only "$commit" "$folder/")
  echo "$name: $n files from $repo@$commit:$folder -> $dest" >&2
done

# The hdrgen response curve shipped with the DSLR set.
eos_git="$mirrors/radiantlab+HDRICalibrationTool/repo"
if [ -d "$eos_git" ]; then
  git -C "$eos_git" show 81cc27b3c652acd5f7d6cc3c6ec777558208e2da:example/response_function_files/Response_function.rsp \
    > "$out/radiantlab-eos/Response_function.rsp"
fi

# Memorial Church (film scans, no EXIF): Debevec & Malik's exposure times,
# 32 s for memorial0061 halving down to 1/1024 s for memorial0076
# (memorial.hdr_image_list.txt of the original distribution gives 1/t).
if [ -d "$out/memorial" ]; then
  : > "$out/memorial/times.txt"
  t=32
  for i in $(seq 61 76); do
    printf 'memorial00%d.png %s\n' "$i" "$(python3 -c "print(repr($t))")" >> "$out/memorial/times.txt"
    t="$t/2"
  done
fi

# EXIF of every JPEG set: the independent truth for the EXIF reader.
for dir in "$out"/*/; do
  name="$(basename "$dir")"
  [ "$name" = memorial ] && continue
  ls "$dir" | grep -qi '\.jpe\?g$' || continue
  (cd "$dir" && exiftool -q -csv -FileName -ExposureTime -FNumber -ISO -Orientation -Make -Model ./*.[Jj][Pp][Gg] \
     | sed 's|^\./||' > exposures.csv)
  python3 - "$dir" <<'PY'
import csv, sys, pathlib
from fractions import Fraction
d = pathlib.Path(sys.argv[1])
rows = sorted(csv.DictReader(open(d / "exposures.csv")), key=lambda r: r["FileName"])
cols = ["FileName", "ExposureTime", "FNumber", "ISO", "Orientation", "Make", "Model"]
with open(d / "exposures.csv", "w", newline="") as f:
    w = csv.writer(f, lineterminator="\n")
    w.writerow(["file"] + cols[1:])
    for r in rows:
        w.writerow([r[c] for c in cols])
n0 = Fraction(rows[0]["FNumber"])
seen = {}
with open(d / "times.txt", "w") as f, open(d / "dropped.txt", "w") as drop:
    for r in rows:
        rel = Fraction(r["ExposureTime"]) * Fraction(r["ISO"]) / 100 * n0**2 / Fraction(r["FNumber"]) ** 2
        # Phones quantize what they record: two frames of a bracket can carry
        # the same ExposureTime and ISO though their pictures differ. Every
        # tool needs distinct exposures, so the later frame is left out.
        if rel in seen:
            drop.write(f"{r['FileName']} same EXIF exposure as {seen[rel]}\n")
            continue
        seen[rel] = r["FileName"]
        f.write(f"{r['FileName']} {float(rel)!r}\n")
PY
done
echo "sets in $out" >&2
