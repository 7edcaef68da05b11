#!/usr/bin/env python3
"""Curve agreement in stops between the response curves of each set.

Every curve is ln(relative exposure) per 8-bit code, defined up to an
additive constant (the unknown scale of exposure). For a pair of curves
(a, b), per channel, over the codes LO..HI (default 10..245; Memorial 16..245) where both are
finite: d = a − b; the offset is removed by least squares (the mean of d);
the figures are the RMS and the largest |d − mean d|, divided by ln 2
(stops). The table gives the worst channel.

Reads `<set>/<curve>.csv` (Campanile's `hdr calibrate` CSV, or peers.py's
`code,ln_exposure_r,ln_exposure_g,ln_exposure_b`); standard library only.

    python3 validation/hdr/compare_curves.py [--dir SETS] [--lo 10 --hi 245] [--csv OUT] [SET...]
"""

import argparse
import csv
import math
import os
import pathlib
import sys

CURVES = [
    ("campanile_debevec", "Campanile Debevec"),
    ("campanile_robertson", "Campanile Robertson"),
    ("opencv_debevec", "OpenCV Debevec"),
    ("opencv_robertson", "OpenCV Robertson"),
    ("pfstools_robertson", "pfstools Robertson"),
    ("hdrgen_rsp", "hdrgen .rsp (maker)"),
    ("hdrgen_rerun", "hdrgen re-run on the set"),
]

# Pairs reported: Campanile against every peer, then the peers against the
# maker's curve (how well the peers themselves agree with it).
PAIRS = [
    ("campanile_debevec", "hdrgen_rsp"),
    ("campanile_debevec", "opencv_debevec"),
    ("campanile_debevec", "opencv_robertson"),
    ("campanile_debevec", "pfstools_robertson"),
    ("campanile_debevec", "campanile_robertson"),
    ("opencv_debevec", "hdrgen_rsp"),
    ("opencv_robertson", "hdrgen_rsp"),
    ("pfstools_robertson", "hdrgen_rsp"),
    ("campanile_robertson", "hdrgen_rsp"),
    ("opencv_debevec", "opencv_robertson"),
    # hdrgen itself on the set's frames (hdrgen_rerun.sh), against the maker's
    # .rsp and Campanile.
    ("campanile_debevec", "hdrgen_rerun"),
    ("campanile_robertson", "hdrgen_rerun"),
    ("opencv_robertson", "hdrgen_rerun"),
    ("hdrgen_rerun", "hdrgen_rsp"),
]


def read_curve(path):
    """{code: (ln_r, ln_g, ln_b)} from either CSV layout; NaN kept."""
    rows = [ln for ln in path.read_text().splitlines() if ln and not ln.startswith("#")]
    reader = csv.DictReader(rows)
    out = {}
    for r in reader:
        try:
            out[int(r["code"])] = tuple(float(r[f"ln_exposure_{c}"]) for c in "rgb")
        except (KeyError, ValueError) as e:
            raise SystemExit(f"compare_curves.py: {path}: bad row {r}: {e}")
    return out


def agreement(a, b, lo, hi):
    """Per channel (rms_stops, max_stops, n) after removing the mean offset."""
    res = []
    for c in range(3):
        d = [
            a[z][c] - b[z][c]
            for z in range(lo, hi + 1)
            if z in a and z in b and math.isfinite(a[z][c]) and math.isfinite(b[z][c])
        ]
        if len(d) < 10:
            res.append((math.nan, math.nan, len(d)))
            continue
        m = sum(d) / len(d)
        r = [x - m for x in d]
        rms = math.sqrt(sum(x * x for x in r) / len(r)) / math.log(2)
        mx = max(abs(x) for x in r) / math.log(2)
        res.append((rms, mx, len(d)))
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sets", nargs="*")
    ap.add_argument(
        "--dir",
        default=os.environ.get(
            "CAMPANILE_HDR_SETS", os.path.join(os.environ.get("TMPDIR", "/tmp"), "campanile-validation", "hdr")
        ),
    )
    ap.add_argument("--lo", type=int, default=10)
    ap.add_argument("--hi", type=int, default=245)
    ap.add_argument("--csv", help="also write every figure (per channel) to this CSV")
    ap.add_argument(
        "--range",
        action="append",
        default=["memorial=16:245"],
        help="SET=LO:HI, codes for one set (default memorial=16:245: its scans never hold codes 1-11)",
    )
    a = ap.parse_args()
    root = pathlib.Path(a.dir)
    names = a.sets or sorted(p.name for p in root.iterdir() if (p / "campanile_debevec.csv").exists())
    label = dict(CURVES)
    ranges = {}
    for r in a.range:
        k, v = r.split("=")
        lo, hi = v.split(":")
        ranges[k] = (int(lo), int(hi))
    rows = []
    print(f"Curve agreement in stops (log2), codes {a.lo}–{a.hi} unless the row says, offset removed by least squares; worst of R, G, B.\n")
    print("| set | codes | curve A | curve B | RMS (stops) | max (stops) | R / G / B RMS |")
    print("|---|---|---|---|---|---|---|")
    for name in names:
        d = root / name
        curves = {k: read_curve(d / f"{k}.csv") for k, _ in CURVES if (d / f"{k}.csv").exists()}
        for ka, kb in PAIRS:
            if ka not in curves or kb not in curves:
                continue
            lo, hi = ranges.get(name, (a.lo, a.hi))
            per = agreement(curves[ka], curves[kb], lo, hi)
            worst_rms = max(p[0] for p in per)
            worst_max = max(p[1] for p in per)
            print(
                f"| {name} | {lo}–{hi} | {label[ka]} | {label[kb]} | {worst_rms:.3f} | {worst_max:.3f} | "
                + " / ".join(f"{p[0]:.3f}" for p in per)
                + " |"
            )
            for c, p in zip("rgb", per):
                rows.append([name, lo, hi, ka, kb, c, f"{p[0]:.4f}", f"{p[1]:.4f}", p[2]])
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["set", "lo", "hi", "curve_a", "curve_b", "channel", "rms_stops", "max_stops", "codes"])
            w.writerows(rows)


if __name__ == "__main__":
    sys.exit(main())
