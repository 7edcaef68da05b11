#!/usr/bin/env bash
# Time and peak memory on a real bracket (issue 23): Campanile `hdr calibrate`
# then `hdr merge` (release build) against OpenCV CalibrateDebevec +
# MergeDebevec (Python, same files, same exposures, same thread count; OpenCV
# writes Radiance .hdr, its wheel has no EXR writer, Campanile OpenEXR), each
# step a process of its own timed by /usr/bin/time -v (wall clock, maximum
# resident set size), REPEATS times, in one run. Machine load (uptime) is
# recorded before and after. Prints a markdown table.
#
#   validation/hdr/fetch_sets.sh           # the sets, outside the repository
#   bench/hdr_real/run.sh [SET [REPEATS [THREADS]]]   # default radiantlab-eos 3 2
#
# Both tools are given the set's times.txt (the same exposures; Campanile
# would read the same nominal times from EXIF).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
set_name="${1:-radiantlab-eos}"
repeats="${2:-3}"
threads="${3:-2}"
sets="${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}"
d="$sets/$set_name"
[ -f "$d/times.txt" ] || { echo "run.sh: no $d/times.txt: run validation/hdr/fetch_sets.sh first" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "run.sh: needs /usr/bin/time (Debian: time)" >&2; exit 2; }
venv="$("$root/bench/venv.sh" opencv-python-headless numpy)"
# BIN=path skips the build and runs that binary instead.
if [ -z "${BIN:-}" ]; then
  (cd "$root" && cargo build -j 1 --quiet --release --bin campanile)
fi
bin="${BIN:-$root/target/release/campanile}"
out="$(mktemp -d "${TMPDIR:-/tmp}/campanile-hdr-real.XXXXXX")"
trap 'rm -rf "$out"' EXIT

files=(); times=()
while read -r f t; do files+=("$d/$f"); times+=("$t"); done < "$d/times.txt"
tlist="$(IFS=,; echo "${times[*]}")"
read -r w h < <(exiftool -s3 -ImageWidth -ImageHeight "${files[0]}" | tr '\n' ' '; echo)
mp="$(echo "scale=1; $w * $h / 1000000" | bc)"

measure() { # label step cmd...
  local label="$1" step="$2"; shift 2
  /usr/bin/time -v -o "$out/time.txt" "$@" > /dev/null 2> "$out/stderr.txt" || {
    echo "run.sh: $label $step failed:" >&2; tail -5 "$out/stderr.txt" >&2; exit 1; }
  local wall rss
  wall="$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$out/time.txt" | awk -F: '{ if (NF==3) print $1*3600+$2*60+$3; else print $1*60+$2 }')"
  rss="$(awk -F': ' '/Maximum resident set size/ {print $2}' "$out/time.txt")"
  printf '%s|%s|%.2f|%.0f\n' "$label" "$step" "$wall" "$(echo "$rss / 1024" | bc -l)" | tee -a "$out/rows.txt" >&2
}

echo "load before: $(uptime)"
export OMP_NUM_THREADS="$threads" RAYON_NUM_THREADS="$threads"
for r in $(seq "$repeats"); do
  measure campanile calibrate "$bin" hdr calibrate "${files[@]}" --times "$tlist" -o "$out/c.csv" --plot "$out/c.svg"
  measure campanile merge "$bin" hdr merge "${files[@]}" --times "$tlist" --curve "$out/c.csv" -o "$out/c.exr"
  measure opencv calibrate "$venv/bin/python" "$here/opencv_steps.py" calibrate "$d" "$out/o.csv" "$threads"
  measure opencv merge "$venv/bin/python" "$here/opencv_steps.py" merge "$d" "$out/o.csv" "$out/o.hdr" "$threads"
done
echo "load after: $(uptime)"
echo "OpenCV $("$venv/bin/python" -c 'import cv2; print(cv2.__version__)') with cv2.setNumThreads($threads); Campanile with RAYON_NUM_THREADS=$threads; $(nproc) cores"
echo
echo "| set | frames | MP | tool | step | wall s (median of $repeats) | wall s (all) | peak RSS MB (max) |"
echo "|---|---|---|---|---|---|---|---|"
for tool in campanile opencv; do
  for step in calibrate merge; do
    grep "^$tool|$step|" "$out/rows.txt" | python3 -c "
import sys, statistics
rows = [l.strip().split('|') for l in sys.stdin if l.strip()]
walls = [float(r[2]) for r in rows]; rss = [float(r[3]) for r in rows]
print(f'| $set_name | ${#files[@]} | $mp | $tool | $step | {statistics.median(walls):.1f} | {\", \".join(f\"{w:.1f}\" for w in walls)} | {max(rss):.0f} |')"
  done
done
python3 - "$out/rows.txt" <<'PY'
import sys, statistics
rows = [l.strip().split("|") for l in open(sys.argv[1]) if l.strip()]
med = lambda tool, step: statistics.median(float(r[2]) for r in rows if r[0] == tool and r[1] == step)
c = med("campanile", "calibrate") + med("campanile", "merge")
o = med("opencv", "calibrate") + med("opencv", "merge")
print(f"\ncalibrate + merge (medians): Campanile {c:.1f} s, OpenCV {o:.1f} s, ratio Campanile/OpenCV {c / o:.2f}")
PY
