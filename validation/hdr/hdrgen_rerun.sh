#!/usr/bin/env bash
# hdrgen's own response curve for a set, derived by hdrgen from the set's
# frames (hdrgen -r FILE with FILE absent), to compare with the .rsp the set
# ships. hdrgen is the WebAssembly build in radiantlab/HDRICalibrationTool
# @ 81cc27b3 (public/wasm/hdrgen.{js,wasm}, radiantlab/hdrgen v1.0.0-13-gad214f2,
# see its public/wasm/versions.json), read from the same git snapshot as
# fetch_sets.sh and run with Node (no browser).
#
#   validation/hdr/hdrgen_rerun.sh [SET [NAME [HDRGEN_FLAGS...]]]
#
# Defaults: SET radiantlab-eos, NAME hdrgen_rerun, flags -a (no alignment:
# a tripod bracket; the maker's EXIF times, exposure adjustment on, as
# hdrgen's defaults). Writes <set>/NAME.rsp and, via hdrgen_rsp.py,
# <set>/NAME.csv (ln exposure per code as hdrgen evaluates it).
# ~1 min for the 18 × 21 MP EOS set. Needs node (>= 18) and python3.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
sets="${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}"
mirrors="${MIRRORS:-/work/.mirror}"
set_name="${1:-radiantlab-eos}"
name="${2:-hdrgen_rerun}"
shift $(( $# > 2 ? 2 : $# ))
flags=("$@")
[ ${#flags[@]} -gt 0 ] || flags=(-a)
git_dir="$mirrors/radiantlab+HDRICalibrationTool/repo"
commit=81cc27b3c652acd5f7d6cc3c6ec777558208e2da
d="$sets/$set_name"
[ -f "$d/times.txt" ] || { echo "hdrgen_rerun.sh: $d/times.txt missing (run fetch_sets.sh)" >&2; exit 2; }
wasm="$(mktemp -d)"
trap 'rm -rf "$wasm"' EXIT
for f in hdrgen.js hdrgen.wasm; do
  git -C "$git_dir" show "$commit:public/wasm/$f" > "$wasm/$f"
done
files=()
while read -r f _; do [ -n "$f" ] && files+=("$d/$f"); done < "$d/times.txt"
node "$here/hdrgen_rerun.mjs" "$wasm" "$d/$name.rsp" "${flags[@]}" -- "${files[@]}"
python3 - "$d/$name.rsp" "$d/$name.csv" "$here" <<'PY'
import pathlib, sys
sys.path.insert(0, sys.argv[3])
import hdrgen_rsp
rsp, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
ln = hdrgen_rsp.ln_curve(rsp)
with open(out, "w") as f:
    f.write(f"# hdrgen response derived by hdrgen from this set ({rsp.name}; as hdrgen evaluates it)\n")
    f.write("code,ln_exposure_r,ln_exposure_g,ln_exposure_b\n")
    for z, v in enumerate(ln):
        f.write(f"{z}," + ",".join(f"{x:.9f}" for x in v) + "\n")
print(f"wrote {out}")
PY
cat "$d/$name.rsp"
