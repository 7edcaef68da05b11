#!/usr/bin/env python3
"""The resampling detector (process/src/hdr/resampled.rs) on real files.

Runs the example `resampled_statistic` (the statistic of
`second_difference_autocorrelation` on the central 512² crop of the green
channel, as `check_not_resampled` does) on

- every frame of every real set, as the camera (or scanner) wrote it, and
- truly resampled copies of them: Pillow resize by 0.5, 0.37 and 0.75 with
  bilinear, bicubic and Lanczos filters, saved as PNG (lossless, so only the
  resampling acts); plus bicubic 0.5 saved as JPEG quality 92 (the common
  "resized for the web" case). To keep it quick, each frame is first cut to
  a central square large enough that the resized copy still has 512² pixels
  of content around its centre (cutting moves no pixel).

Then prints the two distributions, the false-positive rate (camera files
flagged) and the detection rate (resampled flagged) at the current limit
−0.5 and at the threshold that best separates them (largest
detection − false-positive rate), and writes every figure to a CSV.

    venv=$(bench/venv.sh numpy pillow)
    cargo build -j 1 --release -p campanile-process --example resampled_statistic
    "$venv/bin/python" validation/hdr/resampled.py [--csv OUT.csv] [SET...]
"""

import argparse
import csv
import io
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image

FACTORS = (0.5, 0.37, 0.75)
FILTERS = {"bilinear": Image.BILINEAR, "bicubic": Image.BICUBIC, "lanczos": Image.LANCZOS}
LIMIT = -0.5


def sets_root():
    return pathlib.Path(
        os.environ.get(
            "CAMPANILE_HDR_SETS",
            os.path.join(os.environ.get("TMPDIR", "/tmp"), "campanile-validation", "hdr"),
        )
    )


def statistic(example, paths):
    r = subprocess.run([example, *map(str, paths)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"resampled.py: {example} failed ({r.returncode}): {r.stderr[-500:]}")
    out = {}
    for row in csv.DictReader(io.StringIO(r.stdout)):
        out[row["file"]] = row
    return out


def central(im, side):
    w, h = im.size
    s = min(side, w, h)
    x0, y0 = (w - s) // 2, (h - s) // 2
    return im.crop((x0, y0, x0 + s, y0 + s))


def summary(values):
    v = np.array(values)
    return f"n={v.size}, min {v.min():.3f}, q25 {np.percentile(v, 25):.3f}, median {np.median(v):.3f}, q75 {np.percentile(v, 75):.3f}, max {v.max():.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sets", nargs="*")
    ap.add_argument("--csv", default=None)
    ap.add_argument("--extra", nargs="*", default=[], help="more camera files (e.g. the committed crops)")
    ap.add_argument(
        "--example",
        default=str(pathlib.Path(__file__).resolve().parents[2] / "target" / "release" / "examples" / "resampled_statistic"),
    )
    a = ap.parse_args()
    root = sets_root()
    names = a.sets or sorted(p.name for p in root.iterdir() if (p / "times.txt").exists())
    originals = []
    for name in names:
        d = root / name
        for line in (d / "times.txt").read_text().splitlines():
            if line.strip():
                originals.append((name, d / line.split()[0]))
    for f in a.extra:
        originals.append(("fixture", pathlib.Path(f)))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        made = []  # (set, source, factor, filter, path)
        for i, (name, src) in enumerate(originals):
            im = Image.open(src).convert("RGB")
            for fac in FACTORS:
                side = int(np.ceil(640 / fac)) + 16
                base = central(im, side)
                size = (max(1, round(base.width * fac)), max(1, round(base.height * fac)))
                for fname, flt in FILTERS.items():
                    p = tmp / f"{i:04d}_{fac}_{fname}.png"
                    base.resize(size, flt).save(p)
                    made.append((name, src, fac, fname, p))
            base = central(im, int(np.ceil(640 / 0.5)) + 16)
            p = tmp / f"{i:04d}_0.5_bicubic_q92.jpg"
            base.resize((base.width // 2, base.height // 2), Image.BICUBIC).save(p, quality=92)
            made.append((name, src, 0.5, "bicubic+jpeg92", p))
        orig_stats = statistic(a.example, [s for _, s in originals])
        res_stats = statistic(a.example, [m[4] for m in made])
    for name, src in originals:
        r = orig_stats[str(src)]
        rows.append([name, src.name, "camera", 1.0, "", r["width"], r["height"], r["rows"], r["columns"], r["mean"], r["pairs"]])
    for name, src, fac, fname, p in made:
        r = res_stats[str(p)]
        rows.append([name, src.name, "resampled", fac, fname, r["width"], r["height"], r["rows"], r["columns"], r["mean"], r["pairs"]])
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["set", "file", "kind", "factor", "filter", "width", "height", "rows", "columns", "mean", "pairs"])
            w.writerows(rows)
    cam = [float(r[9]) for r in rows if r[2] == "camera" and r[9] != ""]
    res = [float(r[9]) for r in rows if r[2] == "resampled" and r[9] != ""]
    no_verdict = sum(1 for r in rows if r[9] == "")
    print(f"camera files:    {summary(cam)}")
    print(f"resampled files: {summary(res)}")
    print(f"no verdict (too few pairs): {no_verdict}")
    print()
    print("| set | kind | filter | factor | n | min | median | max | flagged at −0.5 |")
    print("|---|---|---|---|---|---|---|---|---|")
    groups = {}
    for r in rows:
        if r[9] == "":
            continue
        key = (r[0], r[2], r[4], r[3])
        groups.setdefault(key, []).append(float(r[9]))
    for key in sorted(groups, key=lambda k: (k[0], k[1], k[2], k[3])):
        v = np.array(groups[key])
        print(
            f"| {key[0]} | {key[1]} | {key[2] or '—'} | {key[3]} | {v.size} | {v.min():.3f} | {np.median(v):.3f} | {v.max():.3f} | {int((v > LIMIT).sum())}/{v.size} |"
        )
    cam, res = np.array(cam), np.array(res)
    print()

    def rates(th):
        return float((cam > th).mean()), float((res > th).mean())

    fp, det = rates(LIMIT)
    print(f"at the limit {LIMIT}: false positives {fp:.1%} of camera files ({int((cam > LIMIT).sum())}/{cam.size}), detection {det:.1%} of resampled ({int((res > LIMIT).sum())}/{res.size})")
    cands = np.unique(np.concatenate([cam, res]))
    best = max(cands, key=lambda th: rates(th)[1] - rates(th)[0])
    fp, det = rates(best)
    print(f"best threshold {best:.3f} (flag when mean > it): false positives {fp:.1%}, detection {det:.1%}")
    print(f"separable: {'yes' if cam.max() < res.min() else 'no'} (camera max {cam.max():.3f}, resampled min {res.min():.3f})")


if __name__ == "__main__":
    sys.exit(main())
