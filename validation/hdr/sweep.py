#!/usr/bin/env python3
"""Campanile's calibration parameters against the maker's curve and the pixels.

For each configuration below, `campanile hdr calibrate` (Debevec–Malik unless
the row says) on the full set with --times from times.txt; then, per channel:

- `maker`: RMS in stops of (curve − hdrgen's curve) over codes LO..HI, offset
  removed by least squares (as compare_curves.py; the .rsp as hdrgen
  evaluates it, hdrgen_rsp.py);
- `default`: the same against Campanile's default curve (samples 4000, λ 3,
  seed 0): how far the parameter moves the curve; the seeds give the noise;
- `pixels`: the RMS pixel-pair error of consistency.py, `pair` and `exif`
  readings, on consistency.py's cached uniform samples.

Rows `blend_maker_α` are no calibration: (1 − α)·default + α·maker, what
tuning Campanile's curve toward the maker's would cost in pixel consistency
(α = 1 is the maker's curve).

    venv=$(bench/venv.sh opencv-python-headless numpy)
    BIN=/work/main/target/release/campanile "$venv/bin/python" validation/hdr/sweep.py \
        [--set radiantlab-eos] [--csv OUT.csv] [--md OUT.md]

Curves go to `<set>/sweep/<name>.csv` (kept: a second run only recomputes
the figures). Needs consistency.py's sample cache for the same --samples and
--seed (run consistency.py first).
"""

import argparse
import csv
import math
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import consistency  # noqa: E402
import hdrgen_rsp  # noqa: E402

CONFIGS = [
    ("default", []),
    ("seed1", ["--seed", "1"]),
    ("seed2", ["--seed", "2"]),
    ("samples16k", ["--samples", "16000"]),
    ("samples64k", ["--samples", "64000"]),
    ("samples64k_seed1", ["--samples", "64000", "--seed", "1"]),
    ("lambda1", ["--lambda", "1"]),
    ("lambda10", ["--lambda", "10"]),
    ("lambda30", ["--lambda", "30"]),
    ("lambda100", ["--lambda", "100"]),
    ("fit_times", ["--fit-times"]),
    ("robertson", ["--method", "robertson"]),
]

BLENDS = [0.1, 0.2, 0.3, 0.5, 1.0]


def agreement(a, b, lo, hi):
    d = a[lo : hi + 1] - b[lo : hi + 1]
    d = d - d.mean(axis=0)
    return np.sqrt((d * d).mean(axis=0)) / math.log(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--set", default="radiantlab-eos")
    ap.add_argument("--samples", type=int, default=400000, help="consistency.py's sample cache")
    ap.add_argument("--seed", type=int, default=1, help="consistency.py's sample cache")
    ap.add_argument("--lo", type=int, default=10)
    ap.add_argument("--hi", type=int, default=245)
    ap.add_argument("--only", help="comma-separated configuration names")
    ap.add_argument("--csv")
    ap.add_argument("--md")
    a = ap.parse_args()
    binary = os.environ.get("BIN", str(HERE.parent.parent / "target" / "release" / "campanile"))
    d = consistency.sets_root() / a.set
    files, times = consistency.read_times(d)
    cache = d / f"consistency_samples_{a.seed}_{a.samples}.npz"
    if not cache.exists():
        raise SystemExit(f"sweep.py: {cache} missing: run consistency.py --samples {a.samples} --seed {a.seed} first")
    codes = consistency.sample_codes(files, a.samples, a.seed, cache)
    maker = np.array(hdrgen_rsp.ln_curve(d / "Response_function.rsp"))
    out_dir = d / "sweep"
    out_dir.mkdir(exist_ok=True)
    tlist = ",".join(repr(float(t)) for t in times)
    configs = CONFIGS
    if a.only:
        keep = a.only.split(",")
        configs = [c for c in CONFIGS if c[0] in keep or c[0] == "default"]
    curves, secs = {}, {}
    for name, extra in configs:
        path = out_dir / f"{name}.csv"
        if not path.exists():
            cmd = [binary, "hdr", "calibrate", *map(str, files), "--times", tlist, "-o", str(path), *extra]
            t0 = time.time()
            r = subprocess.run(cmd, capture_output=True, text=True)
            secs[name] = time.time() - t0
            (out_dir / f"{name}.log").write_text(r.stdout + r.stderr)
            if r.returncode != 0:
                raise SystemExit(f"sweep.py: {name}: exit {r.returncode}: {r.stderr.strip()[-400:]}")
            print(f"  {name}: {secs[name]:.0f} s", file=sys.stderr)
        curves[name] = consistency.read_ln_curve(path)
    # Tuning toward the maker, for what it costs in pixel consistency:
    # (1 − α)·default + α·maker, per channel.
    for alpha in BLENDS:
        name = f"blend_maker_{alpha:g}"
        curves[name] = (1 - alpha) * curves["default"] + alpha * maker
        configs = configs + [(name, None)]
    valid = np.ones(256, bool)
    for v in list(curves.values()) + [maker]:
        valid &= np.isfinite(v).all(axis=1)
    ln_t = np.log(times)
    rows = []
    lines = [
        f"Campanile parameters, set {a.set}: curve vs maker and vs default (stops RMS, codes {a.lo}–{a.hi}, offset removed), "
        f"and pixel-pair RMS error (consistency.py, {a.samples} uniform pixels, seed {a.seed}).\n",
        "| configuration | vs maker R / G / B | vs default R / G / B | pixels `pair` R / G / B | pixels `exif` R / G / B |",
        "|---|---|---|---|---|",
    ]
    for name, _ in configs:
        c = curves[name]
        vm = agreement(c, maker, a.lo, a.hi)
        vd = agreement(c, curves["default"], a.lo, a.hi)
        px = {}
        for reading, fit in (("pair", True), ("exif", False)):
            es, _ = consistency.pair_errors(codes, ln_t, c, a.lo, a.hi, valid, fit)
            px[reading] = [float(np.sqrt(np.mean(e * e))) for e in es]
        rows.append([name, *vm, *vd, *px["pair"], *px["exif"]])
        fmt = lambda v, p=3: " / ".join(f"{x:.{p}f}" for x in v)  # noqa: E731
        lines.append(f"| {name} | {fmt(vm)} | {fmt(vd)} | {fmt(px['pair'], 4)} | {fmt(px['exif'], 4)} |")
    text = "\n".join(lines)
    print(text)
    if a.md:
        pathlib.Path(a.md).write_text(text + "\n")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(
                ["config"]
                + [f"{k}_{c}" for k in ("vs_maker", "vs_default", "pixels_pair", "pixels_exif") for c in "rgb"]
            )
            for r in rows:
                w.writerow([r[0]] + [f"{x:.5f}" for x in r[1:]])


if __name__ == "__main__":
    sys.exit(main())
