#!/usr/bin/env python3
"""Curve-free consistency of response curves with the pixels of a bracket.

What: for a pixel well exposed in two adjacent exposures a (longer, t_a) and
b (shorter, t_b) of a static bracket, a response curve g (ln relative
exposure per code) predicts the radiance ratio exp(g(z_a) − g(z_b)); the
camera says t_a / t_b. The error of one pixel pair, per channel, is

    e = (g(z_a) − g(z_b) − ln(t_a / t_b)) / ln 2        [stops]

No curve is the reference: every curve is judged by the same pixels. The
pixels are uniform random positions over the full frame (numpy Generator,
--seed, --samples), independent of how any tool picks its samples; every
adjacent pair of exposures is used, and a pixel pair counts in a channel when
its code lies in LO..HI (default 10..245) in both exposures. All curves are
judged on the same pixel pairs (codes where any curve is not finite are left
out for all).

Three readings of t_a / t_b:

- `exif`: the times of `<set>/times.txt` (what exiftool reports, what every
  tool was calibrated with). The Canon writes nominal values (13, 6, 3.2 s …
  1/1250, 1/2500, 1/5000 s) whose ratios are not the camera's steps.
- `apex`: the same times rounded to the 1/3-stop grid 2^(k/3) s that the
  camera's shutter uses (13 → 12.70, 6 → 6.35, 1/1250 → 1/1290 …).
- `pair`: one ratio per adjacent pair fitted from the data for each curve
  (the mean of g(z_a) − g(z_b) over all three channels of that pair, one
  ratio for R, G and B together, as hdrgen adjusts its exposures). What is
  left is the error of the curve's shape alone, including the balance of one
  channel against the others; an error of the times cannot hide in it.

Curves: every `<set>/<name>.csv` that exists among campanile_debevec,
campanile_robertson, opencv_debevec, opencv_robertson, pfstools_robertson
(peers.py, campanile_curves.sh), hdrgen_rerun and hdrgen_rerun_noadj
(hdrgen_rerun.sh: hdrgen's own fit on the set, with and without its
exposure adjustment `-e`);
the maker's hdrgen curve read from `<set>/Response_function.rsp` twice: as
hdrgen evaluates it (hdrgen_rsp.py, from panlib phdrimg.h/.cpp:
x = (code + 0.5)/256, linear toe through zero below code 19; `hdrgen_rsp`)
and as peers.py read it before (x = code/255, no toe; `hdrgen_code255`);
plus any `--curve NAME=PATH` (Campanile's CSV
or `code,ln_exposure_r,ln_exposure_g,ln_exposure_b`).

Run (bench venv, outside the repository; sets from fetch_sets.sh):

    venv=$(bench/venv.sh opencv-python-headless numpy)
    "$venv/bin/python" validation/hdr/consistency.py [--set radiantlab-eos] \
        [--samples 400000] [--seed 1] [--lo 10 --hi 245] \
        [--curve NAME=PATH ...] [--csv OUT.csv] [--md OUT.md] [--svg OUT.svg]

The sampled codes are cached in `<set>/consistency_samples_<seed>_<n>.npz`
(first run decodes every frame once: ~1 min for the 18 × 21 MP EOS set).

Prints (and writes with --md) markdown tables, stops:
1. per curve, per time reading and channel: RMS, mean (bias) and median |e|
   over all pixel pairs, and the number of pairs;
2. per curve, blue and the other channels, the mean e and the RMS by code of
   the longer exposure z_a (bins 10–31, 32–63, … 224–HI), `pair` reading.
--svg draws the mean error by code (8-code bins, `pair` reading), one line
per curve, one panel per channel. --csv writes every figure in long form: reading, curve, channel, bin_lo,
bin_hi, n, rms_stops, mean_stops, median_abs_stops.
"""

import argparse
import csv
import math
import os
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import hdrgen_rsp  # noqa: E402

LN2 = math.log(2.0)
FILE_CURVES = [
    "campanile_debevec",
    "campanile_robertson",
    "opencv_debevec",
    "opencv_robertson",
    "pfstools_robertson",
    "hdrgen_rerun",
    "hdrgen_rerun_noadj",
]
BINS = [(10, 31), (32, 63), (64, 95), (96, 127), (128, 159), (160, 191), (192, 223), (224, 255)]


def sets_root():
    return pathlib.Path(
        os.environ.get(
            "CAMPANILE_HDR_SETS",
            os.path.join(os.environ.get("TMPDIR", "/tmp"), "campanile-validation", "hdr"),
        )
    )


def read_times(set_dir):
    files, times = [], []
    for n, line in enumerate((set_dir / "times.txt").read_text().splitlines(), 1):
        if line.strip():
            parts = line.split()
            if len(parts) != 2:
                raise SystemExit(f"consistency.py: {set_dir / 'times.txt'} line {n}: expected 'FILE SECONDS', found {line!r}")
            files.append(set_dir / parts[0])
            times.append(float(parts[1]))
    return files, np.array(times)


def read_ln_curve(path):
    """(256, 3) ln exposure, R, G, B, from Campanile's CSV or peers.py's."""
    rows = [ln for ln in path.read_text().splitlines() if ln and not ln.startswith("#")]
    head = rows[0].split(",")
    try:
        idx = [head.index(f"ln_exposure_{c}") for c in "rgb"]
    except ValueError:
        raise SystemExit(f"consistency.py: {path}: header {head} has no ln_exposure_r/g/b")
    ln = np.array([[float(r.split(",")[i]) for i in idx] for r in rows[1:]])
    if ln.shape != (256, 3):
        raise SystemExit(f"consistency.py: {path}: {ln.shape[0]} codes, expected 256")
    return ln


def rsp_curve_code255(path):
    """The .rsp as peers.py read it before (x = code/255, no toe): kept to
    show what that reading changed."""
    x = np.arange(256) / 255.0
    ln = np.full((256, 3), np.nan)
    for c, coef in enumerate(hdrgen_rsp.read_rsp(path)):
        f = np.polyval(coef, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            ln[:, c] = np.where(f > 0, np.log(f), np.nan)
    return ln


def sample_codes(files, n, seed, cache):
    """codes[frame, sample, channel] (uint8, RGB) at n uniform random pixels."""
    if cache.exists():
        z = np.load(cache)
        return z["codes"]
    import cv2

    rng = np.random.default_rng(seed)
    codes = None
    for k, f in enumerate(files):
        im = cv2.imread(str(f), cv2.IMREAD_COLOR)
        if im is None:
            raise SystemExit(f"consistency.py: OpenCV cannot read {f}")
        if codes is None:
            h, w = im.shape[:2]
            ys = rng.integers(0, h, n)
            xs = rng.integers(0, w, n)
            codes = np.empty((len(files), n, 3), np.uint8)
            shape = im.shape
        elif im.shape != shape:
            raise SystemExit(f"consistency.py: {f}: {im.shape[1]}×{im.shape[0]}, the first frame is {shape[1]}×{shape[0]}")
        codes[k] = im[ys, xs, ::-1]  # BGR -> RGB
        print(f"  sampled {f.name}", file=sys.stderr)
    np.savez_compressed(cache, codes=codes)
    return codes


def apex_times(t):
    """Round to the camera's 1/3-stop grid 2^(k/3) s."""
    return 2.0 ** (np.round(3.0 * np.log2(t)) / 3.0)


def pair_errors(codes, ln_t, curve, lo, hi, valid_code, fit_pair):
    """Per channel: arrays (e_stops, z_a) over every adjacent pair."""
    order = np.argsort(-ln_t)  # longest first
    es = [[] for _ in range(3)]
    zs = [[] for _ in range(3)]
    for i in range(len(order) - 1):
        a, b = order[i], order[i + 1]
        d_lnt = ln_t[a] - ln_t[b]
        per = []
        for c in range(3):
            za = codes[a, :, c].astype(np.int64)
            zb = codes[b, :, c].astype(np.int64)
            m = (za >= lo) & (za <= hi) & (zb >= lo) & (zb <= hi) & valid_code[za] & valid_code[zb]
            per.append((curve[za[m], c] - curve[zb[m], c], za[m]))
        if fit_pair:
            allg = np.concatenate([p[0] for p in per])
            if allg.size == 0:
                continue
            d_lnt = allg.mean()
        for c in range(3):
            g, za = per[c]
            es[c].append((g - d_lnt) / LN2)
            zs[c].append(za)
    return [np.concatenate(e) for e in es], [np.concatenate(z) for z in zs]


def stats(e):
    if e.size == 0:
        return (0, math.nan, math.nan, math.nan)
    return (e.size, float(np.sqrt(np.mean(e * e))), float(e.mean()), float(np.median(np.abs(e))))


def fine_bins(es, zs, lo, hi, width=8):
    """Per channel: [(bin centre, mean e, n)] over bins of `width` codes."""
    out = []
    for e, z in zip(es, zs):
        pts = []
        for b0 in range(lo, hi + 1, width):
            m = (z >= b0) & (z < min(b0 + width, hi + 1))
            if m.sum() >= 200:
                pts.append((b0 + (min(b0 + width, hi + 1) - b0 - 1) / 2, float(e[m].mean()), int(m.sum())))
        out.append(pts)
    return out


COLOURS = {
    "campanile_debevec": "#1f77b4",
    "campanile_robertson": "#17becf",
    "opencv_debevec": "#ff7f0e",
    "opencv_robertson": "#bcbd22",
    "pfstools_robertson": "#9467bd",
    "hdrgen_rsp": "#d62728",
    "hdrgen_code255": "#e377c2",
    "hdrgen_rerun": "#8c564b",
    "hdrgen_rerun_noadj": "#7f7f7f",
}


def plot_svg(fine, a):
    """Three panels (R, G, B): mean pixel-pair error (stops) against the code
    of the longer exposure, one line per curve."""
    pw, ph, ml, mt, gap = 300, 220, 50, 30, 30
    ymin, ymax = -0.3, 0.3
    w = ml + 3 * (pw + gap) + 140
    h = mt + ph + 50
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="11">']
    o.append(f'<rect width="{w}" height="{h}" fill="white"/>')
    o.append(
        f'<text x="{ml}" y="16" font-size="13">Mean pixel-pair error (stops) vs code of the longer exposure, '
        f"set {a.set}, `pair` reading ({a.samples} uniform pixels)</text>"
    )
    for p, ch in enumerate("RGB"):
        x0 = ml + p * (pw + gap)
        sx = lambda z: x0 + (z - a.lo) / (a.hi - a.lo) * pw  # noqa: E731
        sy = lambda v: mt + (ymax - min(max(v, ymin), ymax)) / (ymax - ymin) * ph  # noqa: E731
        o.append(f'<rect x="{x0}" y="{mt}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>')
        for v in (-0.2, -0.1, 0.0, 0.1, 0.2):
            o.append(
                f'<line x1="{x0}" x2="{x0 + pw}" y1="{sy(v):.1f}" y2="{sy(v):.1f}" stroke="{"#444" if v == 0 else "#ddd"}"/>'
            )
            if p == 0:
                o.append(f'<text x="{x0 - 5}" y="{sy(v) + 4:.1f}" text-anchor="end">{v:+.1f}</text>')
        for z in (32, 64, 128, 192, 245):
            o.append(f'<text x="{sx(z):.1f}" y="{mt + ph + 14}" text-anchor="middle">{z}</text>')
        o.append(f'<text x="{x0 + pw / 2}" y="{mt + ph + 30}" text-anchor="middle">{ch}: code z_a</text>')
        for name, per in fine.items():
            pts = " ".join(f"{sx(z):.1f},{sy(v):.1f}" for z, v, _ in per[p])
            sw = 2.2 if name in ("hdrgen_rsp", "campanile_debevec") else 1.2
            o.append(f'<polyline points="{pts}" fill="none" stroke="{COLOURS.get(name, "#000")}" stroke-width="{sw}"/>')
    lx = ml + 3 * (pw + gap)
    for i, name in enumerate(fine):
        y = mt + 10 + 16 * i
        o.append(f'<line x1="{lx}" x2="{lx + 20}" y1="{y}" y2="{y}" stroke="{COLOURS.get(name, "#000")}" stroke-width="2"/>')
        o.append(f'<text x="{lx + 24}" y="{y + 4}">{name}</text>')
    o.append("</svg>")
    return "\n".join(o) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--set", default="radiantlab-eos")
    ap.add_argument("--samples", type=int, default=400000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--lo", type=int, default=10)
    ap.add_argument("--hi", type=int, default=245)
    ap.add_argument("--curve", action="append", default=[], help="NAME=PATH, an extra curve CSV")
    ap.add_argument("--only", help="comma-separated curve names to report (default all)")
    ap.add_argument("--csv")
    ap.add_argument("--md")
    ap.add_argument("--svg", help="plot of the mean error by code of the longer exposure (8-code bins, `pair` reading)")
    a = ap.parse_args()
    d = sets_root() / a.set
    files, times = read_times(d)
    curves = {}
    for name in FILE_CURVES:
        if (d / f"{name}.csv").exists():
            curves[name] = read_ln_curve(d / f"{name}.csv")
    rsp = d / "Response_function.rsp"
    if rsp.exists():
        try:
            curves["hdrgen_rsp"] = np.array(hdrgen_rsp.ln_curve(rsp))
            curves["hdrgen_code255"] = rsp_curve_code255(rsp)
        except ValueError as e:
            raise SystemExit(f"consistency.py: {e}")
    for spec in a.curve:
        name, _, path = spec.partition("=")
        if not path:
            raise SystemExit(f"consistency.py: --curve {spec!r}: expected NAME=PATH")
        curves[name] = read_ln_curve(pathlib.Path(path))
    if a.only:
        keep = a.only.split(",")
        curves = {k: v for k, v in curves.items() if k in keep}
    valid = np.ones(256, bool)
    for v in curves.values():
        valid &= np.isfinite(v).all(axis=1)
    codes = sample_codes(files, a.samples, a.seed, d / f"consistency_samples_{a.seed}_{a.samples}.npz")
    readings = {
        "exif": (np.log(times), False),
        "apex": (np.log(apex_times(times)), False),
        "pair": (np.log(times), True),
    }
    rows = []
    out = []
    out.append(
        f"Pixel-pair consistency, set {a.set}: {a.samples} uniform random pixels (seed {a.seed}), "
        f"{len(files) - 1} adjacent pairs, codes {a.lo}–{a.hi} in both exposures; stops.\n"
    )
    out.append("| reading | curve | R RMS / mean | G RMS / mean | B RMS / mean | B median abs | pairs (B) |")
    out.append("|---|---|---|---|---|---|---|")
    binned = {}
    fine = {}
    for rname, (ln_t, fit) in readings.items():
        for cname, curve in curves.items():
            es, zs = pair_errors(codes, ln_t, curve, a.lo, a.hi, valid, fit)
            if rname == "pair":
                fine[cname] = fine_bins(es, zs, a.lo, a.hi)
            cells = []
            for c, ch in enumerate("rgb"):
                n, rms, mean, med = stats(es[c])
                rows.append([rname, cname, ch, a.lo, a.hi, n, rms, mean, med])
                cells.append((n, rms, mean, med))
                for lo, hi in BINS:
                    hi = min(hi, a.hi)
                    m = (zs[c] >= lo) & (zs[c] <= hi)
                    s = stats(es[c][m])
                    rows.append([rname, cname, ch, lo, hi, *s])
                    binned[(rname, cname, ch, lo)] = s
            out.append(
                f"| {rname} | {cname} | "
                + " | ".join(f"{x[1]:.4f} / {x[2]:+.4f}" for x in cells)
                + f" | {cells[2][3]:.4f} | {cells[2][0]} |"
            )
    for ch in "bg":
        out.append(f"\nBy code of the longer exposure, channel {ch.upper()}, `pair` reading: mean e / RMS (stops).\n")
        out.append("| curve | " + " | ".join(f"{lo}–{min(hi, a.hi)}" for lo, hi in BINS) + " |")
        out.append("|---|" + "---|" * len(BINS))
        for cname in curves:
            cells = [binned[("pair", cname, ch, lo)] for lo, _ in BINS]
            out.append(f"| {cname} | " + " | ".join(f"{s[2]:+.3f} / {s[1]:.3f}" for s in cells) + " |")
        n_row = [binned[("pair", next(iter(curves)), ch, lo)][0] for lo, _ in BINS]
        out.append("| pairs | " + " | ".join(str(n) for n in n_row) + " |")
    text = "\n".join(out)
    print(text)
    if a.md:
        pathlib.Path(a.md).write_text(text + "\n")
    if a.svg:
        pathlib.Path(a.svg).write_text(plot_svg(fine, a))
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["reading", "curve", "channel", "bin_lo", "bin_hi", "n", "rms_stops", "mean_stops", "median_abs_stops"])
            for r in rows:
                w.writerow(r[:6] + [f"{x:.5f}" for x in r[6:]])


if __name__ == "__main__":
    sys.exit(main())
