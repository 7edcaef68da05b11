"""Independent sky references for `campanile sky fit` (issue 22).

Two sources that share no code with Campanile:

* RADIANCE `gendaylit` (Perez all-weather sky, one sky per colour channel),
  rendered with `oconv` + `rtrace` from the `pyradiance` wheel;
* the CIE standard general sky (CIE S 011/E:2003 = ISO 15469:2004), all 15
  types, written here from the standard's published formula and table.

    python generate.py OUT_DIR            # the full set (~2000 samples a sky)
    python generate.py --fixtures OUT_DIR # the small committed subset

Writes OUT_DIR/manifest.csv and OUT_DIR/samples/<id>.csv. Deterministic: the
same command writes the same bytes. Conventions (Campanile's DESIGN.md):
x east, y north, z up; azimuth from north through east; angles in degrees.
"""

import argparse
import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

# ---------------------------------------------------------------- geometry

COS_XI_MIN = 0.3  # a calibrated sky camera's usable cap: cos(zenith) >= 0.3
GAMMA_MIN_DEG = 1.0  # outside the solar disc and its flare
XI_MAX_DEG = math.degrees(math.acos(COS_XI_MIN))  # 72.54°


def direction(zenith_deg, azimuth_deg):
    """Unit vector (x east, y north, z up) of a direction given by its zenith
    angle and its azimuth from north through east, in degrees."""
    z, p = math.radians(zenith_deg), math.radians(azimuth_deg)
    return (math.sin(z) * math.sin(p), math.sin(z) * math.cos(p), math.cos(z))


def angle_deg(u, v):
    c = sum(a * b for a, b in zip(u, v))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def grid(rings, per_radian):
    """Equal-area-ish grid over the cap cos(zenith) >= COS_XI_MIN: the zenith,
    then `rings` rings evenly spaced up to zenith 72.5°, each with
    round(per_radian * sin(zenith)) directions, every other ring staggered by
    half a step. Angles are rounded to 1e-4° (the files hold them exactly)."""
    step = 72.5 / rings
    out = [(0.0, 0.0)]
    for k in range(1, rings + 1):
        xi = round(k * step, 4)
        n = max(6, round(per_radian * math.sin(math.radians(xi))))
        off = 0.5 if k % 2 else 0.0
        for j in range(n):
            out.append((xi, round((j + off) * 360.0 / n, 4)))
    assert all(math.cos(math.radians(x)) >= COS_XI_MIN for x, _ in out)
    return out


FULL_GRID = (33, 110)  # ~2000 directions a sky before the sun cut
FIXTURE_GRID = (17, 58)  # ~550

# ---------------------------------------------------------------- Perez bins

BIN_EDGES = [1.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2, math.inf]


def bin_of(eps):
    for i in range(8):
        if BIN_EDGES[i] <= eps < BIN_EDGES[i + 1]:
            return i + 1
    raise ValueError(eps)


def green_eps(b):
    lo, hi = BIN_EDGES[b - 1], BIN_EDGES[b]
    return 8.0 if math.isinf(hi) else round((lo + hi) / 2, 4)


def channel_eps(b, g=None):
    """Per-channel clearness: red clearer (x1.15), blue hazier (x0.87), as a
    real sky is across wavelengths, kept inside green's bin with a margin of
    10% of the bin's width where the bin is too narrow for those ratios (the
    last bin is taken to end at 12, gendaylit's upper limit)."""
    lo, hi = BIN_EDGES[b - 1], min(BIN_EDGES[b], 12.0)
    g = green_eps(b) if g is None else g
    r = min(1.15 * g, hi - 0.1 * (hi - lo))
    bl = max(0.87 * g, lo + 0.1 * (hi - lo))
    return {"r": round(r, 4), "g": g, "b": round(bl, 4)}


def channel_delta(delta):
    """Per-channel brightness: blue brighter than green brighter than red."""
    return {"r": round(0.85 * delta, 4), "g": delta, "b": round(1.15 * delta, 4)}


def effective_delta(eps, delta):
    """Δ as gendaylit's coefficient code uses it: first limited to
    [0.01, 0.6] (check_parametrization), then raised to 0.2 for
    1.065 < ε < 2.8 (coeff_lum_perez, 'correction de modele de Perez')."""
    d = min(max(delta, 0.01), 0.6)
    if 1.065 < eps < 2.8 and d < 0.2:
        d = 0.2
    return d


# ---------------------------------------------------------------- CIE sky

# CIE S 011/E:2003 (ISO 15469:2004), table 1: six gradation groups (a, b) and
# six indicatrix groups (c, d, e); the 15 standard types combine them.
CIE_GRADATION = {
    "I": (4.0, -0.70),
    "II": (1.1, -0.80),
    "III": (0.0, -1.00),
    "IV": (-1.0, -0.55),
    "V": (-1.0, -0.32),
    "VI": (-1.0, -0.15),
}
CIE_INDICATRIX = {
    1: (0.0, -1.0, 0.00),
    2: (2.0, -1.5, 0.15),
    3: (5.0, -2.5, 0.30),
    4: (10.0, -3.0, 0.45),
    5: (16.0, -3.0, 0.30),
    6: (24.0, -2.8, 0.15),
}
CIE_TYPES = {
    1: ("I", 1),
    2: ("I", 2),
    3: ("II", 1),
    4: ("II", 2),
    5: ("III", 1),
    6: ("III", 2),
    7: ("III", 3),
    8: ("III", 4),
    9: ("IV", 2),
    10: ("IV", 3),
    11: ("IV", 4),
    12: ("V", 4),
    13: ("V", 5),
    14: ("VI", 5),
    15: ("VI", 6),
}


def cie_coefficients(t):
    g, i = CIE_TYPES[t]
    return CIE_GRADATION[g] + CIE_INDICATRIX[i]


def cie_gradation(a, b, xi):
    """φ(Z) = 1 + a exp(b / cos Z) for 0 <= Z < π/2, φ(π/2) = 1."""
    c = math.cos(xi)
    return 1.0 + a * math.exp(b / c) if c > 0 else 1.0


def cie_indicatrix(c, d, e, chi):
    """f(χ) = 1 + c [exp(d χ) - exp(d π/2)] + e cos² χ."""
    return 1.0 + c * (math.exp(d * chi) - math.exp(d * math.pi / 2)) + e * math.cos(chi) ** 2


def cie_relative(t, xi, chi, zs):
    """L / Lz = f(χ) φ(Z) / (f(Zs) φ(0)); all angles in radians."""
    a, b, c, d, e = cie_coefficients(t)
    return (cie_indicatrix(c, d, e, chi) * cie_gradation(a, b, xi)) / (
        cie_indicatrix(c, d, e, zs) * cie_gradation(a, b, 0.0)
    )


# ---------------------------------------------------------------- perezlum.cal


def perezlum(args, d):
    """skybright of RADIANCE's perezlum.cal for direction d, from the ten
    real arguments gendaylit printed: (norm, ground, A3..A7, sun x, y, z).
    Returns (skybright, intersky)."""
    a1, a2, a3, a4, a5, a6, a7, sx, sy, sz = args
    dz = d[2]
    cosg = d[0] * sx + d[1] * sy + d[2] * sz
    gamma = math.acos(max(-1.0, min(1.0, cosg)))
    inter = a1 * (1 + a3 * math.exp(a4 / (dz if dz > 0.01 else 0.01))) * (
        1 + a5 * math.exp(a6 * gamma) + a7 * cosg * cosg
    )
    wa, wb = (dz + 1.01) ** 10, (dz + 1.01) ** -10
    return (wa * inter + wb * a2) / (wa + wb), inter


# ---------------------------------------------------------------- RADIANCE


def radiance_env():
    """PATH and RAYPATH for the binaries and .cal files in the pyradiance
    wheel (importing pyradiance sets both)."""
    import pyradiance  # noqa: F401  (sets RAYPATH and PATH)

    env = dict(os.environ)
    for tool in ("gendaylit", "oconv", "rtrace"):
        if shutil.which(tool, path=env["PATH"]) is None:
            sys.exit(f"generate.py: {tool} not found in the pyradiance wheel")
    return env


GLOW = "skyfunc glow sky_glow 0 0 4 1 1 1 0\nsky_glow source sky 0 0 4 0 0 1 180\n"


def gendaylit(env, alt, az_radiance, eps, delta):
    """Runs gendaylit -ang ALT AZ -P EPS DELTA -O 1 -s and returns its sky
    description and the ten real arguments of skyfunc."""
    cmd = ["gendaylit", "-ang", repr(alt), repr(az_radiance), "-P", repr(eps), repr(delta), "-O", "1", "-s"]
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()}")
    lines = p.stdout.splitlines()
    try:
        i = lines.index("2 skybright perezlum.cal")
        nums = lines[i + 2].split()
    except (ValueError, IndexError):
        raise RuntimeError(f"{' '.join(cmd)}: no perezlum skyfunc in output:\n{p.stdout}")
    if nums[0] != "10":
        raise RuntimeError(f"{' '.join(cmd)}: expected 10 real arguments, got {nums[0]}")
    args = [float(x) for x in nums[1:11]]
    warn = " ".join(l.strip() for l in p.stderr.splitlines() if l.strip())
    return p.stdout, args, warn


def rtrace(env, sky_rad, dirs, tmp):
    """Radiance of each direction seen from the origin, as rtrace printed it
    (first component; the sky is grey)."""
    rad = os.path.join(tmp, "sky.rad")
    oct_ = os.path.join(tmp, "sky.oct")
    with open(rad, "w") as f:
        f.write(sky_rad + "\n" + GLOW)
    with open(oct_, "wb") as f:
        subprocess.run(["oconv", rad], env=env, stdout=f, check=True)
    rays = "".join(f"0 0 0 {x!r} {y!r} {z!r}\n" for x, y, z in dirs)
    p = subprocess.run(
        ["rtrace", "-h", "-ab", "0", "-ov", oct_], env=env, input=rays, capture_output=True, text=True, check=True
    )
    vals = [l.split()[0] for l in p.stdout.splitlines() if l.strip()]
    if len(vals) != len(dirs):
        raise RuntimeError(f"rtrace returned {len(vals)} values for {len(dirs)} rays")
    return vals


# ---------------------------------------------------------------- sky lists

FULL_ELEVATIONS = [2, 4, 10, 20, 30, 45, 60, 75, 88]
FULL_DELTAS = [0.05, 0.15, 0.3, 0.5]
AZIMUTHS = [180, 135, 225, 90, 270, 30, 330, 0, 200, 160]  # from north through east
CIE_FULL_ELEVATIONS = [2, 10, 30, 45, 60, 75, 88]

# Fixtures: every bin at two or three elevations (low 2-4°, ~30°, high 45-88°).
FIXTURE_SKIES = [
    # (bin, elevation, delta, azimuth)
    (1, 4, 0.15, 135),
    (1, 30, 0.3, 180),
    (1, 75, 0.05, 225),
    (2, 2, 0.05, 90),  # intermediate, Δ clamped to 0.2 in every channel
    (2, 30, 0.15, 200),
    (2, 60, 0.3, 270),
    (3, 4, 0.3, 330),
    (3, 45, 0.05, 160),
    (4, 2, 0.15, 30),
    (4, 30, 0.5, 180),
    (4, 88, 0.3, 0),
    (5, 10, 0.3, 225),
    (5, 60, 0.15, 135),
    (6, 4, 0.15, 270),
    (6, 30, 0.3, 90),
    (6, 75, 0.15, 200),
    (7, 2, 0.15, 160),
    (7, 30, 0.15, 180),
    (7, 60, 0.15, 330),
    (8, 4, 0.12, 225),  # clear, low sun
    (8, 30, 0.12, 135),
    (8, 60, 0.12, 180),  # clear, 60°
]
DENVER = dict(lat=39.74, lon=-104.99, when="2026-06-21T19:00:00Z", eps=6.5, delta=0.12)
FIXTURE_CIE = [(t, e, az) for t in (1, 5, 8, 12, 15) for e, az in ((10, 135), (45, 200))]


def denver_sun():
    """Apparent sun position at Denver, June 21 19:00 UTC (pvlib's SPA),
    rounded to 1e-3° so the fixtures do not move with pvlib's last digits."""
    import pandas as pd
    import pvlib

    t = pd.DatetimeIndex([DENVER["when"]])
    sp = pvlib.solarposition.get_solarposition(t, DENVER["lat"], DENVER["lon"], method="nrel_numpy")
    return round(float(sp["apparent_elevation"].iloc[0]), 3), round(float(sp["azimuth"].iloc[0]), 3)


def gendaylit_specs(fixtures):
    specs = []
    if fixtures:
        for b, el, dl, az in FIXTURE_SKIES:
            specs.append((f"gdl-bin{b}-el{el:02d}-d{round(dl * 100):02d}-az{az:03d}", b, el, dl, az, None))
        el, az = denver_sun()
        specs.append(("gdl-bin8-denver-noon", 8, el, DENVER["delta"], az, DENVER["eps"]))
    else:
        k = 0
        for b in range(1, 9):
            for el in FULL_ELEVATIONS:
                for dl in FULL_DELTAS:
                    az = AZIMUTHS[k % len(AZIMUTHS)]
                    k += 1
                    specs.append((f"gdl-bin{b}-el{el:02d}-d{round(dl * 100):02d}-az{az:03d}", b, el, dl, az, None))
    return specs


def cie_specs(fixtures):
    if fixtures:
        return [(f"cie{t:02d}-el{e:02d}-az{az:03d}", t, e, az) for t, e, az in FIXTURE_CIE]
    out, k = [], 0
    for t in range(1, 16):
        for e in CIE_FULL_ELEVATIONS:
            az = AZIMUTHS[k % len(AZIMUTHS)]
            k += 1
            out.append((f"cie{t:02d}-el{e:02d}-az{az:03d}", t, e, az))
    return out


# ---------------------------------------------------------------- generation

CHANNELS = ("r", "g", "b")
PER_CHANNEL = ["eps", "delta_asked", "delta_eff", "a", "b", "c", "d", "e", "norm", "ground"]
MANIFEST = (
    ["id", "source", "bin", "cie_type", "sun_zenith_deg", "sun_azimuth_deg", "sun_x_printed", "sun_y_printed",
     "sun_z_printed", "n_samples", "max_blend", "n_nonpositive"]
    + [f"{k}_{ch}" for ch in CHANNELS + ("y",) for k in PER_CHANNEL]
    + ["warnings"]
)
REFUSED = ["id", "channel", "eps", "delta", "sun_elevation_deg", "sun_azimuth_deg", "reason"]


def kept(dirs_deg, sun):
    out = []
    for zen, az in dirs_deg:
        d = direction(zen, az)
        if angle_deg(d, sun) >= GAMMA_MIN_DEG:
            out.append((zen, az, d))
    return out


def fmt(x):
    return repr(float(x))


def make_gendaylit(env, spec, dirs_deg, outdir):
    sid, b, el, dl, az, eps_override = spec
    eps = channel_eps(b, eps_override)
    assert all(bin_of(e) == b for e in eps.values()), (sid, eps)
    dls = channel_delta(dl)
    # gendaylit lowers the sun to 87° above the horizon; we ask for what it uses.
    el_eff = min(el, 87.0)
    az_rad = (az - 180.0) % 360.0  # RADIANCE: degrees west of south
    sun = direction(90.0 - el_eff, az)
    pts = kept(dirs_deg, sun)
    row = {"id": sid, "source": "gendaylit", "bin": bin_of(eps["g"]), "cie_type": "",
           "sun_zenith_deg": fmt(round(90.0 - el_eff, 6)), "sun_azimuth_deg": fmt(az), "n_samples": len(pts)}
    cols, warns, max_blend, nonpos, refused = {}, [], 0.0, 0, []
    with tempfile.TemporaryDirectory() as tmp:
        for ch in CHANNELS:
            text, args, warn = gendaylit(env, el_eff, az_rad, eps[ch], dls[ch])
            printed_sun = args[7:10]
            if max(abs(p - s) for p, s in zip(printed_sun, sun)) > 2e-6:
                raise RuntimeError(f"{sid}/{ch}: gendaylit's sun {printed_sun} is not ours {sun}")
            if warn:
                warns.append(f"{ch}: {warn}")
            if args[0] == 0 and all(v == 0 for v in args[1:7]):
                # gendaylit's "error sky": all coefficients zero, a black sky.
                refused.append({"id": sid, "channel": ch, "eps": fmt(eps[ch]), "delta": fmt(dls[ch]),
                                "sun_elevation_deg": fmt(el_eff), "sun_azimuth_deg": fmt(az), "reason": warn})
                continue
            if refused:
                continue
            vals = rtrace(env, text, [p[2] for p in pts], tmp)
            cols[ch] = vals
            nonpos += sum(1 for v in vals if float(v) <= 0)
            for _, _, d in pts:
                sb, inter = perezlum(args, d)
                if inter != 0:
                    max_blend = max(max_blend, abs(sb / inter - 1))
            for k, v in zip(("sun_x_printed", "sun_y_printed", "sun_z_printed"), printed_sun):
                if row.setdefault(k, fmt(v)) != fmt(v):
                    raise RuntimeError(f"{sid}/{ch}: gendaylit printed another sun than for the other channels")
            row.update({f"eps_{ch}": fmt(eps[ch]), f"delta_asked_{ch}": fmt(dls[ch]),
                        f"delta_eff_{ch}": fmt(effective_delta(eps[ch], dls[ch]))})
            for k, v in zip(["norm", "ground", "a", "b", "c", "d", "e"], args[:7]):
                row[f"{k}_{ch}"] = fmt(v)
    if refused:
        return None, refused
    row["max_blend"] = f"{max_blend:.6e}"
    row["n_nonpositive"] = nonpos
    row["warnings"] = " | ".join(warns)
    with open(os.path.join(outdir, "samples", f"{sid}.csv"), "w", newline="") as f:
        f.write("zenith_deg,azimuth_deg,r,g,b\n")
        for i, (zen, az_, _) in enumerate(pts):
            f.write(f"{fmt(zen)},{fmt(az_)},{cols['r'][i]},{cols['g'][i]},{cols['b'][i]}\n")
    return row, []


def make_cie(spec, dirs_deg, outdir):
    sid, t, el, az = spec
    zs = math.radians(90.0 - el)
    sun = direction(90.0 - el, az)
    pts = kept(dirs_deg, sun)
    a, b, c, d, e = cie_coefficients(t)
    row = {"id": sid, "source": "cie", "bin": "", "cie_type": t, "sun_zenith_deg": fmt(90.0 - el),
           "sun_azimuth_deg": fmt(az), "n_samples": len(pts), "max_blend": "", "n_nonpositive": 0,
           "a_y": fmt(a), "b_y": fmt(b), "c_y": fmt(c), "d_y": fmt(d), "e_y": fmt(e), "norm_y": "1.0", "warnings": ""}
    with open(os.path.join(outdir, "samples", f"{sid}.csv"), "w", newline="") as f:
        f.write("zenith_deg,azimuth_deg,y\n")
        for zen, az_, dv in pts:
            # At the zenith the angle to the sun is the sun's zenith angle by definition.
            chi = zs if zen == 0.0 else math.radians(angle_deg(dv, sun))
            v = cie_relative(t, math.radians(zen), chi, zs)
            row["n_nonpositive"] += v <= 0
            f.write(f"{fmt(zen)},{fmt(az_)},{fmt(v)}\n")
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", help="output directory (created; its samples/ is replaced)")
    ap.add_argument("--fixtures", action="store_true", help="the small committed subset")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    env = radiance_env()
    out = args.out
    shutil.rmtree(os.path.join(out, "samples"), ignore_errors=True)
    os.makedirs(os.path.join(out, "samples"))
    dirs_deg = grid(*(FIXTURE_GRID if args.fixtures else FULL_GRID))
    gspecs = gendaylit_specs(args.fixtures)
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as ex:
        made = list(ex.map(lambda s: make_gendaylit(env, s, dirs_deg, out), gspecs))
    rows = [r for r, _ in made if r is not None]
    refused = [x for _, xs in made for x in xs]
    with open(os.path.join(out, "refused.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=REFUSED, lineterminator="\n")
        w.writeheader()
        w.writerows(refused)
    rows += [make_cie(s, dirs_deg, out) for s in cie_specs(args.fixtures)]
    with open(os.path.join(out, "manifest.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=MANIFEST, restval="", lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    n_gdl = sum(1 for r, _ in made if r is not None)
    print(f"generate.py: {len(rows)} skies ({n_gdl} gendaylit, {len(rows) - n_gdl} CIE; "
          f"{len(gspecs) - n_gdl} refused by gendaylit in {len(refused)} channels, listed in refused.csv), "
          f"{len(dirs_deg)} grid directions, into {out}")


if __name__ == "__main__":
    main()
