"""The scipy side of the sky-fit benchmark on the independent references.

    python scipy_fit.py DIR [--start START.csv] [--noise 0.02 --seed S]
                            [--cie-starts 12,1] [--out FITS.csv] [--per-sky] [--reps 5]

DIR holds manifest.csv and samples/<id>.csv (validation/sky/generate.sh's
full set, or validation/sky/fixtures). For every sky and channel it fits the
Perez form of thesis eq. 5.9 with h = 1,

    L(ξ, γ) = Lz [1 + a exp(b / max(cos ξ, 0.01))] [1 + c exp(d γ) + e cos² γ],

with scipy.optimize.least_squares(method="lm") (MINPACK's Levenberg-Marquardt,
analytic Jacobian, default tolerances), residuals (L - y) / y, from the start
given for (id, channel) in START.csv (columns id, channel, lz, a, b, c, d, e),
else from CIE type 12 written in that form, scaled by the median of the data.
The sun is the manifest's (zenith and azimuth from north through east).

Reports per sky and channel the relative error of the fit against the
noise-free samples (median, p95, max of |L / y - 1|), nfev, status and the
time (best of --reps runs, time.perf_counter). With --noise the same again on
samples with that much multiplicative Gaussian noise (seeded per sky and
channel), the error still measured against the noise-free values. A channel
with a sample <= 0 (gendaylit makes a few Perez skies with negative radiance)
is not fitted: its relative residual is undefined; it is listed as skipped.
"""

import argparse
import csv
import math
import os
import sys
import time
import zlib

import numpy as np
import scipy
from scipy.optimize import least_squares

# CIE type 12 (clear sky) in eq. 5.9's form: the standard's
# f(χ) = 1 + c [exp(dχ) - exp(dπ/2)] + e cos²χ divided by 1 - c exp(dπ/2).
# CIE S 011/E:2003 types in the standard's form (a, b, c, d, e); only used as
# starting points here.
CIE_TYPES = {1: (4.0, -0.70, 0.0, -1.0, 0.0), 5: (0.0, -1.0, 0.0, -1.0, 0.0), 8: (0.0, -1.0, 10.0, -3.0, 0.45),
             12: (-1.0, -0.32, 10.0, -3.0, 0.45), 15: (-1.0, -0.15, 24.0, -2.8, 0.15)}
NAMES = ["lz", "a", "b", "c", "d", "e"]


def unit(zen_deg, az_deg):
    z, p = np.radians(zen_deg), np.radians(az_deg)
    return np.stack([np.sin(z) * np.sin(p), np.sin(z) * np.cos(p), np.cos(z)], axis=-1)


def geometry(samples, sky):
    d = unit(samples["zenith_deg"], samples["azimuth_deg"])
    sun = unit(float(sky["sun_zenith_deg"]), float(sky["sun_azimuth_deg"]))
    cos_xi = np.maximum(d[:, 2], 0.01)
    cos_g = np.clip(d @ sun, -1.0, 1.0)
    return cos_xi, np.arccos(cos_g), cos_g


def model_parts(p, cos_xi, gamma, cos_g):
    lz, a, b, c, d, e = p
    eb = np.exp(b / cos_xi)
    ed = np.exp(d * gamma)
    grad = 1 + a * eb
    ind = 1 + c * ed + e * cos_g**2
    return lz, a, c, eb, ed, grad, ind


def model(p, cos_xi, gamma, cos_g):
    lz, _, _, _, _, grad, ind = model_parts(p, cos_xi, gamma, cos_g)
    return lz * grad * ind


def fit_one(y_fit, geo, x0):
    cos_xi, gamma, cos_g = geo
    inv = 1.0 / y_fit

    def res(p):
        return model(p, *geo) * inv - 1.0

    def jac(p):
        lz, a, c, eb, ed, grad, ind = model_parts(p, *geo)
        j = np.empty((len(y_fit), 6))
        j[:, 0] = grad * ind
        j[:, 1] = lz * eb * ind
        j[:, 2] = lz * a * eb / cos_xi * ind
        j[:, 3] = lz * grad * ed
        j[:, 4] = lz * grad * c * gamma * ed
        j[:, 5] = lz * grad * cos_g**2
        return j * inv[:, None]

    with np.errstate(over="ignore", invalid="ignore"):
        return least_squares(res, x0, jac=jac, method="lm")


def cie_in_eq59(t):
    """CIE type t's a-e in eq. 5.9's form (c and e divided by 1 - c exp(dπ/2))."""
    a, b, c, d, e = CIE_TYPES[t]
    k = 1 - c * math.exp(d * math.pi / 2)
    return np.array([a, b, c / k, d, e / k])


def starts_for(y, geo, given, cie_starts):
    """The given start, else each CIE type of cie_starts scaled by the median
    of y over the type's shape."""
    if given is not None:
        return [np.array(given, dtype=float)]
    out = []
    for t in cie_starts:
        shape = model(np.concatenate([[1.0], cie_in_eq59(t)]), *geo)
        out.append(np.concatenate([[np.median(y / shape)], cie_in_eq59(t)]))
    return out


def fit_best(y_fit, geo, x0s):
    """Fits from every start and keeps the lowest cost; nfev is the sum."""
    best, nfev = None, 0
    for x0 in x0s:
        r = fit_one(y_fit, geo, x0)
        nfev += r.nfev
        if best is None or (np.isfinite(r.cost) and not r.cost >= best.cost):
            best = r
    return best, nfev


def load_starts(path):
    if path is None:
        return {}
    out = {}
    with open(path, newline="") as f:
        for i, r in enumerate(csv.DictReader(f), start=2):
            try:
                out[(r["id"], r["channel"])] = [float(r[k]) for k in NAMES]
            except (KeyError, ValueError) as e:
                fail(f"scipy_fit.py: {path} line {i}: needs numbers in columns {', '.join(NAMES)} ({e})")
    return out


def read_samples(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        head = rows[0]
        data = np.array(rows[1:], dtype=float)
    except (OSError, IndexError, ValueError) as e:
        fail(f"scipy_fit.py: {path}: expected a CSV with zenith_deg,azimuth_deg and channel columns of numbers ({e})")
    if "zenith_deg" not in head or "azimuth_deg" not in head or data.ndim != 2 or len(data) == 0:
        fail(f"scipy_fit.py: {path}: header {','.join(head)}: expected zenith_deg, azimuth_deg and at least one sample")
    return {h: data[:, i] for i, h in enumerate(head)}


def run(args):
    manifest = os.path.join(args.dir, "manifest.csv")
    try:
        with open(manifest, newline="") as f:
            skies = list(csv.DictReader(f))
    except OSError as e:
        fail(f"scipy_fit.py: {manifest}: cannot read ({e})")
    for i, sky in enumerate(skies, start=2):
        for k in ("id", "source", "bin", "cie_type", "sun_zenith_deg", "sun_azimuth_deg"):
            v = sky.get(k)
            try:
                if v is None or (k.startswith("sun_") and not math.isfinite(float(v))):
                    raise ValueError
            except ValueError:
                fail(f"scipy_fit.py: {manifest} line {i}: {k} = {v!r}; expected "
                     f"{'a finite number of degrees' if k.startswith('sun_') else 'the column of generate.py'}")
    starts = load_starts(args.start)
    noises = [0.0] + ([args.noise] if args.noise > 0 else [])
    out = []
    for sky in skies:
        s = read_samples(os.path.join(args.dir, "samples", f"{sky['id']}.csv"))
        geo = geometry(s, sky)
        for ch in [c for c in ("r", "g", "b", "y") if c in s]:
            y = s[ch]
            base = {"id": sky["id"], "source": sky["source"], "bin": sky["bin"], "cie_type": sky["cie_type"],
                    "channel": ch, "n": len(y)}
            for noise in noises:
                row = dict(base, noise=noise, seed=args.seed if noise > 0 else "")
                if np.any(y <= 0):
                    row.update(status="skipped", note=f"{int(np.sum(y <= 0))} samples <= 0")
                    out.append(row)
                    continue
                y_fit = y
                if noise > 0:
                    rng = np.random.default_rng([args.seed, zlib.crc32(f"{sky['id']}/{ch}".encode())])
                    y_fit = y * (1 + noise * rng.standard_normal(len(y)))
                x0s = starts_for(y_fit, geo, starts.get((sky["id"], ch)), args.cie_starts)
                best = math.inf
                for _ in range(args.reps):
                    t = time.perf_counter()
                    r, nfev = fit_best(y_fit, geo, x0s)
                    best = min(best, time.perf_counter() - t)
                with np.errstate(over="ignore", invalid="ignore"):
                    err = np.abs(model(r.x, *geo) / y - 1)
                if not np.all(np.isfinite(err)):
                    err = np.full_like(err, np.inf)
                row.update(status=r.status, nfev=nfev, median_err=float(np.median(err)),
                           p95_err=float(np.percentile(err, 95)), max_err=float(np.max(err)),
                           time_ms=best * 1e3, note=r.message if r.status <= 0 else "")
                row.update({k: float(v) for k, v in zip(NAMES, r.x)})
                out.append(row)
    return out


FIELDS = ["id", "source", "bin", "cie_type", "channel", "n", "noise", "seed", "status", "nfev", "median_err",
          "p95_err", "max_err", "time_ms"] + NAMES + ["note"]


def pct(x):
    return f"{100 * x:.3g}%"


GRADATION = {1: "I", 2: "I", 3: "II", 4: "II", 5: "III", 6: "III", 7: "III", 8: "III", 9: "IV", 10: "IV", 11: "IV",
             12: "V", 13: "V", 14: "VI", 15: "VI"}


def group(r):
    """gendaylit: green's Perez bin; CIE: the type's gradation group."""
    if r["source"] == "cie":
        return "gradation " + GRADATION[int(r["cie_type"])]
    return f"bin {r['bin']}"


def summary(rows):
    """One line per (source, group, noise), groups being Perez bins or CIE
    gradation groups, and all of a source: over the fitted channels, the median and
    p95 of the per-channel median error, the p95 and max of the per-channel
    max error, median nfev and time."""
    lines = ["| skies | noise | channels fitted (skipped) | median of median err | p95 of median err "
             "| p95 of max err | max of max err | median nfev | median time / channel |",
             "|---|---|---|---|---|---|---|---|---|"]
    keys = sorted({(r["source"], "all", r["noise"]) for r in rows} | {(r["source"], group(r), r["noise"]) for r in rows})
    for src, grp, noise in keys:
        sel = [r for r in rows if r["source"] == src and r["noise"] == noise and grp in ("all", group(r))]
        ok = [r for r in sel if r["status"] != "skipped"]
        if not ok:
            continue
        med = np.array([r["median_err"] for r in ok])
        mx = np.array([r["max_err"] for r in ok])
        n = int(np.median([r["n"] for r in ok]))
        lines.append(f"| {src} {grp} | {pct(noise)} | {len(ok)} ({len(sel) - len(ok)}) | {pct(np.median(med))} "
                     f"| {pct(np.percentile(med, 95))} | {pct(np.percentile(mx, 95))} | {pct(np.max(mx))} "
                     f"| {int(np.median([r['nfev'] for r in ok]))} "
                     f"| {np.median([r['time_ms'] for r in ok]):.2f} ms ({n} samples) |")
    return "\n".join(lines)


def per_sky(rows):
    lines = ["| sky | ch | noise | status | nfev | median err | p95 err | max err | time |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] == "skipped":
            lines.append(f"| {r['id']} | {r['channel']} | {pct(r['noise'])} | skipped: {r['note']} | | | | | |")
        else:
            lines.append(f"| {r['id']} | {r['channel']} | {pct(r['noise'])} | {r['status']} | {r['nfev']} "
                         f"| {pct(r['median_err'])} | {pct(r['p95_err'])} | {pct(r['max_err'])} | {r['time_ms']:.2f} ms |")
    return "\n".join(lines)


def fail(msg):
    """Bad input or usage: the message on standard error, exit status 2."""
    print(msg, file=sys.stderr)
    sys.exit(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--start", help="CSV with id, channel, lz, a, b, c, d, e")
    ap.add_argument("--noise", type=float, default=0.0, help="relative Gaussian noise, e.g. 0.02")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--cie-starts", default="12", help="CIE types to start from when --start has no row, "
                    "comma-separated, of 1, 5, 8, 12, 15 (default 12; several: the lowest cost is kept, "
                    "nfev and time are the total)")
    ap.add_argument("--reps", type=int, default=5, help="timed runs per fit, the best is kept")
    ap.add_argument("--out", help="CSV to write (default ${TMPDIR:-/tmp}/campanile-validation/scipy_fit.csv, "
                    "outside the repository)")
    ap.add_argument("--per-sky", action="store_true", help="print one table row per sky and channel")
    args = ap.parse_args()
    if not 0 <= args.noise < 1:
        fail(f"scipy_fit.py: --noise {args.noise}: expected a fraction in [0, 1)")
    if args.reps < 1:
        fail(f"scipy_fit.py: --reps {args.reps}: expected at least 1")
    try:
        args.cie_starts = [int(t) for t in args.cie_starts.split(",")]
    except ValueError:
        args.cie_starts = [0]
    if not args.cie_starts or any(t not in CIE_TYPES for t in args.cie_starts):
        fail(f"scipy_fit.py: --cie-starts: expected types among {sorted(CIE_TYPES)}, comma-separated")
    rows = run(args)
    out = args.out or os.path.join(os.environ.get("TMPDIR", "/tmp"), "campanile-validation", "scipy_fit.csv")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS, restval="", lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    print(f"scipy {scipy.__version__}, numpy {np.__version__}: least_squares(method='lm'), analytic Jacobian, "
          f"residuals (L - y) / y, start: {args.start or 'CIE type ' + ','.join(map(str, args.cie_starts))}, "
          f"best of {args.reps} runs; {args.dir}\n")
    print(summary(rows))
    if args.per_sky:
        print()
        print(per_sky(rows))
    print(f"\nwritten: {out}")


if __name__ == "__main__":
    main()
