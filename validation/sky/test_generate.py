"""Tests of the sky reference generator itself, on a generated directory.

    python test_generate.py DIR     # DIR holds manifest.csv and samples/

Each check prints its figure and its tolerance; the exit status is 1 if any
check fails. generate.sh runs this after every generation.
"""

import csv
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import generate as g  # noqa: E402

FAILED = []


def check(name, ok, figure):
    print(f"{'ok  ' if ok else 'FAIL'} {name}: {figure}")
    if not ok:
        FAILED.append(name)


def load(d):
    with open(os.path.join(d, "manifest.csv"), newline="") as f:
        skies = list(csv.DictReader(f))
    out = []
    for s in skies:
        with open(os.path.join(d, "samples", f"{s['id']}.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
        out.append((s, rows))
    return out


def sun_of(s):
    return g.direction(float(s["sun_zenith_deg"]), float(s["sun_azimuth_deg"]))


def test_cie_zenith_is_lz(data):
    """L/Lz at the zenith is exactly 1 for every type and sun elevation, from
    the formula and in the files' zenith sample."""
    worst = 0.0
    for t in range(1, 16):
        for el in (0.5, 2, 10, 30, 45, 60, 75, 88, 90):
            zs = math.radians(90 - el)
            worst = max(worst, abs(g.cie_relative(t, 0.0, zs, zs) - 1.0))
    n = 0
    for s, rows in data:
        if s["source"] == "cie":
            z = [r for r in rows if float(r["zenith_deg"]) == 0.0]
            worst = max(worst, abs(float(z[0]["y"]) - 1.0))
            n += 1
    check("cie zenith = 1·Lz", worst <= 1e-15 and n > 0, f"max |L/Lz - 1| at the zenith {worst:.1e} (tol 1e-15), {n} sky files")


def test_cie12_is_the_1973_clear_sky(data):
    """Type 12 is the CIE clear sky of CIE 110-1994 (Kittler's formula with
    0.91 + 10 exp(-3γ) + 0.45 cos²γ and 1 - exp(-0.32 / cos Z)); the
    standard's f(χ) writes 0.91 as 1 - 10 exp(-3π/2) = 0.91020, so the two
    agree to 5e-4 relative."""
    def old(xi, chi, zs):
        f = lambda x: 0.91 + 10 * math.exp(-3 * x) + 0.45 * math.cos(x) ** 2  # noqa: E731
        return f(chi) * (1 - math.exp(-0.32 / math.cos(xi))) / (f(zs) * (1 - math.exp(-0.32)))

    worst = 0.0
    for el in (10, 30, 60, 85):
        zs = math.radians(90 - el)
        sun = g.direction(90 - el, 0)
        for zen, az in g.grid(*g.FIXTURE_GRID):
            d = g.direction(zen, az)
            chi = math.radians(g.angle_deg(d, sun))
            ours = g.cie_relative(12, math.radians(zen), chi, zs)
            worst = max(worst, abs(ours / old(math.radians(zen), chi, zs) - 1))
    check("cie type 12 = CIE 110 clear sky", worst <= 5e-4, f"max relative difference {worst:.2e} (tol 5e-4)")


def test_gendaylit_sun_is_ours(data):
    """The sun gendaylit printed (x east, y north, z up), from our
    conversion of azimuth 'north through east' to RADIANCE's 'west of south'
    (az_radiance = az - 180°), is the manifest's sun to the 6 printed
    decimals."""
    worst, n = 0.0, 0
    for s, _ in data:
        if s["source"] != "gendaylit":
            continue
        printed = [float(s[k]) for k in ("sun_x_printed", "sun_y_printed", "sun_z_printed")]
        worst = max(worst, max(abs(p - q) for p, q in zip(printed, sun_of(s))))
        n += 1
    check("gendaylit's sun is the manifest's", worst <= 5.0001e-7 and n > 0, f"max component difference {worst:.2e} (tol 5e-7, the printed rounding) over {n} skies")


def test_perezlum_reproduces_rtrace(data):
    """The coefficients gendaylit printed, put through perezlum.cal's formula
    (with the horizon blend) at the sample's direction (zenith and azimuth
    from north through east, as the files give them), give rtrace's value to
    1e-4 relative on every sample: the files' directions are the ones rtrace
    traced. (The sun used is the one gendaylit printed, as rtrace used it:
    near the sun of a sky with c < 0 the value nearly cancels, and the
    printed sun's 6-decimal rounding alone moves it by up to 2e-3.)"""
    worst, n, where = 0.0, 0, ""
    for s, rows in data:
        if s["source"] != "gendaylit":
            continue
        sun = [float(s[k]) for k in ("sun_x_printed", "sun_y_printed", "sun_z_printed")]
        for ch in g.CHANNELS:
            args = [float(s[f"{k}_{ch}"]) for k in ("norm", "ground", "a", "b", "c", "d", "e")] + sun
            for r in rows:
                d = g.direction(float(r["zenith_deg"]), float(r["azimuth_deg"]))
                model, _ = g.perezlum(args, d)
                v = float(r[ch])
                e = abs(model - v) / abs(v) if v != 0 else abs(model)
                n += 1
                if e > worst:
                    worst, where = e, f"{s['id']} {ch} at ({r['zenith_deg']}, {r['azimuth_deg']})"
    check("perezlum.cal reproduces rtrace", worst <= 1e-4 and n > 0, f"max relative error {worst:.2e} (tol 1e-4) over {n} values, worst {where}")


def test_brightest_sample_next_to_sun(data):
    """Where the sky has a circumsolar peak and no negative lobe (gendaylit
    bins 2-8, CIE indicatrix groups 3-6, no sample <= 0) the brightest sample
    lies next to the point of the sampled cap nearest the sun (the sun itself
    when it is inside the cap, else the cap's edge under it): within 5° on
    the full grid (2.2° rings); a grid can only place it within about one
    ring step of the peak, so on a coarser grid the bound is step + 1°."""
    step = min(float(r["zenith_deg"]) for _, rows in data for r in rows if float(r["zenith_deg"]) > 0)
    tol = max(5.0, step + 1.0)
    worst, n, where = 0.0, 0, ""
    for s, rows in data:
        if s["n_nonpositive"] != "0":
            continue
        if s["source"] == "gendaylit" and int(s["bin"]) < 2:
            continue
        if s["source"] == "cie" and g.CIE_TYPES[int(s["cie_type"])][1] < 3:
            continue
        sz, sa = float(s["sun_zenith_deg"]), float(s["sun_azimuth_deg"])
        target = g.direction(min(sz, 72.5), sa)
        for ch in (g.CHANNELS if s["source"] == "gendaylit" else ("y",)):
            top = max(rows, key=lambda r: float(r[ch]))
            a = g.angle_deg(g.direction(float(top["zenith_deg"]), float(top["azimuth_deg"])), target)
            n += 1
            if a > worst:
                worst, where = a, f"{s['id']} {ch}"
    check("brightest sample next to the sun", worst <= tol and n > 0,
          f"max distance {worst:.2f}° (tol {tol:.2f}°, ring step {step:.2f}°) over {n} channels, worst {where}")


def test_samples_in_cap_and_off_sun(data):
    worst_cos, worst_gamma = 1.0, 180.0
    for s, rows in data:
        sun = sun_of(s)
        for r in rows:
            d = g.direction(float(r["zenith_deg"]), float(r["azimuth_deg"]))
            worst_cos = min(worst_cos, d[2])
            worst_gamma = min(worst_gamma, g.angle_deg(d, sun))
    check("samples in the cap, off the sun", worst_cos >= 0.3 and worst_gamma >= 1.0,
          f"min cos ξ {worst_cos:.4f} (≥ 0.3), min γ {worst_gamma:.3f}° (≥ 1°)")


def test_effective_delta_is_gendaylits(data):
    """Where the manifest records a raised Δ (1.065 < ε < 2.8, Δ < 0.2),
    gendaylit asked for that Δ directly prints the same five coefficients."""
    env = g.radiance_env()
    n, bad = 0, []
    for s, _ in data:
        if s["source"] != "gendaylit":
            continue
        for ch in g.CHANNELS:
            if s[f"delta_eff_{ch}"] == s[f"delta_asked_{ch}"]:
                continue
            el = 90 - float(s["sun_zenith_deg"])
            az = (float(s["sun_azimuth_deg"]) - 180) % 360
            _, args, _ = g.gendaylit(env, el, az, float(s[f"eps_{ch}"]), float(s[f"delta_eff_{ch}"]))
            want = [float(s[f"{k}_{ch}"]) for k in "abcde"]
            n += 1
            if args[2:7] != want:
                bad.append(f"{s['id']} {ch}: {args[2:7]} != {want}")
    check("effective Δ is gendaylit's", n > 0 and not bad, f"{n} raised channels, mismatches: {bad or 'none'}")


def main():
    d = sys.argv[1]
    data = load(d)
    for t in (test_cie_zenith_is_lz, test_cie12_is_the_1973_clear_sky, test_gendaylit_sun_is_ours,
              test_perezlum_reproduces_rtrace,
              test_brightest_sample_next_to_sun, test_samples_in_cap_and_off_sun, test_effective_delta_is_gendaylits):
        t(data)
    if FAILED:
        print(f"test_generate.py: {len(FAILED)} check(s) failed: {', '.join(FAILED)}")
        sys.exit(1)
    print(f"test_generate.py: all checks passed on {len(data)} skies in {d}")


if __name__ == "__main__":
    main()
