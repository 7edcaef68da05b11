"""The Campanile side of the sky-fit check on the independent references.

    python campanile_fit.py DIR --campanile PATH/TO/campanile [--out FITS.csv] [--per-sky]

For every sky of DIR (manifest.csv, samples/<id>.csv) runs the command line
as a user would:

    campanile sky fit samples/<id>.csv --sun-zenith-deg Z --sun-azimuth-deg A --out T/<id>.ron
    campanile sky eval T/<id>.ron samples/<id>.csv

and measures, per channel, the relative error of the fitted sky against the
samples (median, p95, max of |L / y - 1|, over all samples, masked or not),
with the model Campanile chose, its masked fraction and the fit's verdict
(exit 0 ok, 3 failed gate). The time is the wall time of the `sky fit`
process divided by its channels (process start, CSV, robust fit and model
choice included): not comparable with scipy_fit.py's in-process LM time; use
a release build. Channels with a sample <= 0 are reported but not scored.
Only the standard library: no venv needed.
"""

import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time


def pct(x):
    return f"{100 * x:.3g}%"


def quantile(v, q):
    v = sorted(v)
    if not v:
        return math.nan
    i = q * (len(v) - 1)
    lo, hi = math.floor(i), math.ceil(i)
    return v[lo] + (v[hi] - v[lo]) * (i - lo)


def read_csv(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"campanile_fit.py: {path}: cannot read ({e})")
    if not rows:
        fail(f"campanile_fit.py: {path}: no rows")
    return rows


def fit_sky(exe, d, sky, tmp):
    samples = os.path.join(d, "samples", f"{sky['id']}.csv")
    ron = os.path.join(tmp, f"{sky['id']}.ron")
    t = time.perf_counter()
    p = subprocess.run([exe, "sky", "fit", samples, "--sun-zenith-deg", sky["sun_zenith_deg"],
                        "--sun-azimuth-deg", sky["sun_azimuth_deg"], "--out", ron], capture_output=True, text=True)
    wall = time.perf_counter() - t
    if p.returncode not in (0, 3):
        return None, wall, p.returncode, p.stderr.strip().splitlines()[-1:] or [""]
    ev = subprocess.run([exe, "sky", "eval", ron, samples], capture_output=True, text=True)
    if ev.returncode != 0:
        return None, wall, ev.returncode, ev.stderr.strip().splitlines()[-1:] or [""]
    with open(ron) as f:
        text = f.read()
    chosen = dict(re.findall(r'channel: "(\w+)".*?chosen: "([^"]+)"', text, flags=re.S))
    masked = dict(re.findall(r'channel: "(\w+)".*?masked_fraction: ([0-9.eE+-]+)', text, flags=re.S))
    fitted = list(csv.DictReader(ev.stdout.splitlines()))
    return (fitted, chosen, masked), wall, p.returncode, []


def fail(msg):
    """Bad input or usage: the message on standard error, exit status 2."""
    print(msg, file=sys.stderr)
    sys.exit(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--campanile", required=True, help="the campanile binary (a release build for timings)")
    ap.add_argument("--out", help="CSV to write (default ${TMPDIR:-/tmp}/campanile-validation/campanile_fit.csv)")
    ap.add_argument("--per-sky", action="store_true")
    args = ap.parse_args()
    if not os.access(args.campanile, os.X_OK):
        fail(f"campanile_fit.py: --campanile {args.campanile}: not an executable file")
    skies = read_csv(os.path.join(args.dir, "manifest.csv"))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for sky in skies:
            samples = read_csv(os.path.join(args.dir, "samples", f"{sky['id']}.csv"))
            chans = [c for c in ("r", "g", "b", "y") if c in samples[0]]
            res, wall, code, msg = fit_sky(args.campanile, args.dir, sky, tmp)
            for ch in chans:
                row = {"id": sky["id"], "source": sky["source"], "bin": sky["bin"], "cie_type": sky["cie_type"],
                       "channel": ch, "n": len(samples), "exit": code, "time_ms": 1e3 * wall / len(chans)}
                try:
                    y = [float(s[ch]) for s in samples]
                except (TypeError, ValueError) as e:
                    fail(f"campanile_fit.py: {sky['id']}.csv column {ch}: expected numbers ({e})")
                if res is None:
                    row.update(status="error", note=" ".join(msg))
                elif min(y) <= 0:
                    row.update(status="not scored", note=f"{sum(v <= 0 for v in y)} samples <= 0")
                else:
                    fitted, chosen, masked = res
                    err = [abs(float(f[ch]) / v - 1) for f, v in zip(fitted, y)]
                    row.update(status="ok" if code == 0 else "failed gate", model=chosen.get(ch, ""),
                               masked=float(masked.get(ch, "nan")), median_err=statistics.median(err),
                               p95_err=quantile(err, 0.95), max_err=max(err))
                rows.append(row)
    out = args.out or os.path.join(os.environ.get("TMPDIR", "/tmp"), "campanile-validation", "campanile_fit.csv")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    fields = ["id", "source", "bin", "cie_type", "channel", "n", "exit", "status", "model", "masked", "median_err",
              "p95_err", "max_err", "time_ms", "note"]
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, restval="", lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    print(f"{args.campanile} sky fit + sky eval on {args.dir}\n")
    print("| skies | channels scored (not) | median of median err | p95 of median err | p95 of max err "
          "| max of max err | median masked | failed gate | median wall time / channel |")
    print("|---|---|---|---|---|---|---|---|---|")
    groups = sorted({(r["source"], "all") for r in rows} | {(r["source"], f"bin {r['bin']}" if r["bin"] else
                    f"type {int(r['cie_type']):02d}") for r in rows})
    for src, grp in groups:
        sel = [r for r in rows if r["source"] == src and grp in ("all", f"bin {r['bin']}" if r["bin"] else
               f"type {int(r['cie_type']):02d}")]
        ok = [r for r in sel if "median_err" in r]
        if not ok:
            continue
        med = [r["median_err"] for r in ok]
        mx = [r["max_err"] for r in ok]
        print(f"| {src} {grp} | {len(ok)} ({len(sel) - len(ok)}) | {pct(statistics.median(med))} "
              f"| {pct(quantile(med, 0.95))} | {pct(quantile(mx, 0.95))} | {pct(max(mx))} "
              f"| {pct(statistics.median(r['masked'] for r in ok))} | {sum(r['status'] == 'failed gate' for r in ok)} "
              f"| {statistics.median(r['time_ms'] for r in ok):.1f} ms |")
    if args.per_sky:
        print("\n| sky | ch | status | model | masked | median err | p95 err | max err |\n|---|---|---|---|---|---|---|---|")
        for r in rows:
            if "median_err" in r:
                print(f"| {r['id']} | {r['channel']} | {r['status']} | {r['model']} | {pct(r['masked'])} "
                      f"| {pct(r['median_err'])} | {pct(r['p95_err'])} | {pct(r['max_err'])} |")
            else:
                print(f"| {r['id']} | {r['channel']} | {r['status']}: {r.get('note', '')} | | | | | |")
    print(f"\nwritten: {out}")


if __name__ == "__main__":
    main()
