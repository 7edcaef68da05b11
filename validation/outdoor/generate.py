"""RADIANCE outdoor reference for `campanile outdoor recover` / `outdoor
render` (issue 31): a building (building.py) under gendaylit's per-channel
Perez skies and sun at five times of one day, four viewpoints, rendered by
rpict with Monte Carlo interreflection.

    python generate.py OUT_DIR [--size 192x128] [--ad 1024] [--ab 6]
    python generate.py --fixtures validation/outdoor/fixtures   # 96x64 committed set

OUT_DIR receives building.obj, building.rad, brick.cal, sky.cal,
scene.ron, photos.ron (every time but the held-out one), photos-heldout.ron,
light.ron, light-fisheye.ron, skies/<HHMM>.ron (+ .rad, fisheye .hdr),
views/<camera>-<HHMM>.hdr (interreflection, mean of two seeds),
views-ab0/<camera>-<HHMM>.hdr (-ab 0: the sun alone), masks/<camera>.png
(255 on target surfaces), truth.json, render.json (commands, gendaylit's
output, timings, Monte Carlo noise, the sky check, the bounce study).
See README.md.
"""

import argparse
import datetime
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

import building as B
from rgbe import read_rgbe, write_png_gray, write_rgbe

CHANNELS = ("r", "g", "b")
SUN_HALF_DEG = 0.2665  # gendaylit's half_sun_angle; the source is 0.533° across
SUN_OMEGA = 2 * math.pi * (1 - math.cos(math.radians(SUN_HALF_DEG)))  # srcsupp.c: ss2 of a distant source

# rpict settings (README, "Render settings").
COMMON = [
    "-pa", "0", "-ps", "1", "-pj", "0", "-pm", "0", "-pd", "0",
    "-dj", "0", "-ds", "0", "-dt", "0", "-dc", "1", "-dr", "0", "-dp", "0",
    "-st", "0", "-i-", "-av", "0", "0", "0",
]


def interreflection_args(ab, ad):
    return ["-ab", str(ab), "-aa", "0", "-ad", str(ad), "-as", "0", "-lr", "0", "-lw", f"{0.4 / ad:.3g}"]


def radiance_env():
    import pyradiance  # noqa: F401  (sets RAYPATH and PATH to the wheel's binaries)

    env = dict(os.environ)
    env["RAYPATH"] = ".:" + env.get("RAYPATH", "")
    for tool in ("gendaylit", "oconv", "rpict", "rtrace"):
        if shutil.which(tool, path=env["PATH"]) is None:
            sys.exit(f"generate.py: {tool} not found in the pyradiance wheel")
    return env


def run(cmd, env, cwd, **kw):
    p = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, **kw)
    if p.returncode != 0:
        err = p.stderr.decode() if isinstance(p.stderr, bytes) else p.stderr
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {err.strip()}")
    return p


# ---------------------------------------------------------------- time and sun


def jdate(month, day):
    return [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334][month - 1] + day


def utc_of_solar(hour):
    """UTC clock time (hours) of local solar time `hour` on DATE, by the
    equation of time gendaylit uses without a year (sun.c `stadj`: solar
    time = standard time + 0.170 sin(4π(J−80)/373) − 0.129 sin(2π(J−8)/355)
    + 12 (meridian − longitude)/π)."""
    jd = jdate(B.DATE[1], B.DATE[2])
    merid, lon_w = math.radians(B.MERIDIAN_WEST_DEG), math.radians(-B.SITE["longitude_deg"])
    stadj = (0.170 * math.sin(4 * math.pi / 373 * (jd - 80)) - 0.129 * math.sin(2 * math.pi / 355 * (jd - 8))
             + 12 / math.pi * (merid - lon_w))
    return hour - stadj - B.UTC_OFFSET_H


def iso_utc(hours):
    t = datetime.datetime(*B.DATE, tzinfo=datetime.timezone.utc) + datetime.timedelta(seconds=round(hours * 3600))
    return t.strftime("%Y-%m-%dT%H:%M:%SZ")


def gendaylit(env, hour, ch):
    cmd = ["gendaylit", str(B.DATE[1]), str(B.DATE[2]), f"+{hour:g}",
           "-a", f"{B.SITE['latitude_deg']:g}", "-o", f"{-B.SITE['longitude_deg']:g}", "-m", f"{B.MERIDIAN_WEST_DEG:g}",
           "-P", repr(B.EPS[ch]), repr(B.DELTA[ch]), "-O", "1", "-g", repr(B.GROUND["rgb".index(ch)])]
    p = run(cmd, env, None, text=True)
    lines = p.stdout.splitlines()
    try:
        i = lines.index("void light solar")
        sun_rad = [float(x) for x in lines[i + 3].split()[1:4]]
        j = lines.index("solar source sun")
        sun_vec = [float(x) for x in lines[j + 3].split()[1:4]]
        k = lines.index("2 skybright perezlum.cal")
        nums = lines[k + 2].split()
    except (ValueError, IndexError):
        raise RuntimeError(f"{' '.join(cmd)}: unexpected output:\n{p.stdout}")
    args = [float(x) for x in nums[1:11]]
    if args[0] == 0 and all(v == 0 for v in args[1:7]):
        raise RuntimeError(f"{' '.join(cmd)}: gendaylit printed its error sky: {p.stderr.strip()}")
    if max(abs(a - b) for a, b in zip(args[7:10], sun_vec)) > 1e-6:
        raise RuntimeError(f"{' '.join(cmd)}: the skyfunc's sun differs from the source's")
    return dict(cmd=" ".join(cmd), stdout=p.stdout, stderr=p.stderr.strip(), sun_radiance=sun_rad[0],
                sun_vec=sun_vec, args=args)


def sun_angles(v):
    """(azimuth from north through east, zenith), degrees, of a unit vector."""
    az = math.degrees(math.atan2(v[0], v[1])) % 360.0
    zen = math.degrees(math.acos(max(-1.0, min(1.0, v[2]))))
    return az, zen


# ---------------------------------------------------------------- sky


def sky_model(args):
    """Eq. 5.9's parameters from gendaylit's ten skyfunc arguments:
    perezlum.cal's `intersky` is A1 (1 + A3 e^(A4/Dz)) (1 + A5 e^(A6 γ) +
    A7 cos²γ), which is eq. 5.9 with h = 1 term by term."""
    a1, _a2, a3, a4, a5, a6, a7 = args[:7]
    return dict(lz=a1, a=a3, b=a4, c=a5, d=a6, e=a7, h=1.0)


def eq59(m, dirs, sun):
    """Eq. 5.9 (cos ξ floored at 0.01) at unit directions (N, 3)."""
    cz = np.maximum(dirs[:, 2], 0.01)
    cg = np.clip(dirs @ np.asarray(sun), -1, 1)
    g = np.arccos(cg)
    return m["lz"] * (1 + m["a"] * np.exp(m["b"] / cz)) * (1 + m["c"] * np.exp(m["d"] * g ** m["h"]) + m["e"] * cg * cg)


def sky_rad(sky, with_sun=True):
    lines = []
    if with_sun:
        rad = " ".join(f"{sky[ch]['sun_radiance']:.6e}" for ch in CHANNELS)
        sv = sky["g"]["sun_vec"]
        lines += ["void light solar\n0\n0\n3 " + rad,
                  f"solar source sun\n0\n0\n4 {sv[0]:f} {sv[1]:f} {sv[2]:f} {2 * SUN_HALF_DEG:g}"]
    real = " ".join(repr(a) for ch in CHANNELS for a in sky[ch]["args"])
    lines += [f"void colorfunc skyfunc\n4 sky_r sky_g sky_b sky.cal\n0\n30 {real}",
              "skyfunc glow sky_glow\n0\n0\n4 1 1 1 0",
              "sky_glow source sky\n0\n0\n4 0 0 1 180",
              "sky_glow source ground_glow\n0\n0\n4 0 0 -1 180"]
    return "\n\n".join(lines) + "\n"


def sky_file(sky, az, zen):
    chans = []
    for ch in CHANNELS:
        m = sky_model(sky[ch]["args"])
        chans.append(
            f"        (channel: \"{ch}\", model: (lz: {m['lz']!r}, a: {m['a']!r}, b: {m['b']!r}, c: {m['c']!r}, "
            f"d: {m['d']!r}, e: {m['e']!r}, h: 1.0), chosen: \"Perez\", reason: \"gendaylit's coefficients "
            f"(-P {B.EPS[ch]!r} {B.DELTA[ch]!r} -O 1), not fitted\", rms_relative: 0.0, samples: 0, masked_fraction: 0.0),"
        )
    return ("// gendaylit's per-channel Perez sky in eq. 5.9's form (validation/outdoor/generate.py)\n"
            f"SkyFile(\n    sun_zenith_deg: {zen!r},\n    sun_azimuth_deg: {az!r},\n    channels: [\n"
            + "\n".join(chans) + "\n    ],\n)\n")


def check_sky(env, sky, tmp):
    """Eq. 5.9 from the SkyFile against rtrace's radiance of the rendered
    sky (sky.cal, the horizon blend included): 36 azimuths × 12 zenith
    angles from 0 to 89.4°. Returns max relative differences by band."""
    zen = np.array([0, 10, 20, 30, 40, 50, 60, 70, 75, 80, 85, 89.4])
    azs = np.arange(0, 360, 10.0)
    Z, A = np.meshgrid(np.radians(zen), np.radians(azs), indexing="ij")
    dirs = np.stack([np.sin(Z) * np.sin(A), np.sin(Z) * np.cos(A), np.cos(Z)], -1).reshape(-1, 3)
    rad = Path(tmp) / "skyonly.rad"
    rad.write_text(sky_rad(sky, with_sun=False))
    with open(Path(tmp) / "skyonly.oct", "wb") as f:
        subprocess.run(["oconv", str(rad)], env=env, cwd=tmp, stdout=f, check=True)
    rays = "".join(f"0 0 0 {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in dirs)
    p = run(["rtrace", "-h", "-ab", "0", "-ov", "skyonly.oct"], env, tmp, input=rays, text=True)
    got = np.array([[float(v) for v in l.split()] for l in p.stdout.splitlines() if l.strip()])
    # gendaylit's own green sky (brightfunc with RADIANCE's perezlum.cal): sky.cal must equal it.
    (Path(tmp) / "native.rad").write_text(
        sky["g"]["stdout"] + "\nskyfunc glow sky_glow\n0\n0\n4 1 1 1 0\n\nsky_glow source sky\n0\n0\n4 0 0 1 180\n")
    with open(Path(tmp) / "native.oct", "wb") as f:
        subprocess.run(["oconv", "native.rad"], env=env, cwd=tmp, stdout=f, check=True)
    q = run(["rtrace", "-h", "-ab", "0", "-ov", "native.oct"], env, tmp, input=rays, text=True)
    native = np.array([float(l.split()[0]) for l in q.stdout.splitlines() if l.strip()])
    out = {"directions": len(dirs), "zenith_deg": zen.tolist(), "azimuth_step_deg": 10,
           "sky_cal_vs_perezlum_cal_green": float(np.max(np.abs(got[:, 1] / native - 1)))}
    wa, wb = (dirs[:, 2] + 1.01) ** 10, (dirs[:, 2] + 1.01) ** -10
    for c, ch in enumerate(CHANNELS):
        want = eq59(sky_model(sky[ch]["args"]), dirs, sky[ch]["sun_vec"])
        rel = np.abs(want / got[:, c] - 1)
        for name, lo in (("cos_xi_gt_0.01", 0.0101), ("cos_xi_ge_0.1", 0.1), ("cos_xi_ge_0.3", 0.3)):
            sel = dirs[:, 2] >= lo
            out.setdefault(name, {})[ch] = float(rel[sel].max())
        blended = (wa * want + wb * sky[ch]["args"][1]) / (wa + wb)
        out.setdefault("eq59_with_the_blend_all", {})[ch] = float(np.max(np.abs(blended / got[:, c] - 1)))
    return out


# ---------------------------------------------------------------- scene files


def write_rad(out):
    lines = ["# validation/outdoor: the issue-31 building, its neighbour and the ground (x east, y north, z up, m)"]
    lines.append("void colorfunc brick_pat\n4 brick_r brick_g brick_b brick.cal\n0\n0")
    for mat, col in B.COLOURS.items():
        mod = "brick_pat" if mat == "brick" else "void"
        lines.append(f"{mod} plastic {mat}\n0\n0\n5 {col[0]:g} {col[1]:g} {col[2]:g} 0 0")
    for group, mat, corners in B.polygons():
        pts = "\n".join("  {:g} {:g} {:g}".format(*p) for p in corners)
        lines.append(f"{mat} polygon {group}\n0\n0\n{3 * len(corners)}\n{pts}")
    (out / "building.rad").write_text("\n\n".join(lines) + "\n")
    (out / "brick.cal").write_text(B.BRICK_CAL)
    (out / "sky.cal").write_text(B.SKY_CAL)


def write_obj(out):
    lines = ["# validation/outdoor building: one group per polygon of building.rad; metres, x east, y north, z up;",
             "# faces counter-clockwise seen from outside (normals outward; the ground's up)"]
    vid = 1
    for group, _, corners in B.polygons():
        lines.append(f"g {group}")
        for p in corners:
            lines.append("v {:g} {:g} {:g}".format(*p))
        lines.append("f " + " ".join(str(vid + i) for i in range(len(corners))))
        vid += len(corners)
    (out / "building.obj").write_text("\n".join(lines) + "\n")


def write_scene(out):
    mats = []
    for m in B.TARGET_MATERIALS:
        mats.append(f"        (name: \"{m}\", model: PseudoBrdf),")
    for m, a in B.KNOWN_ALBEDO.items():
        mats.append(f"        (name: \"{m}\", model: Diffuse, albedo: ({a[0]:.2f}, {a[1]:.2f}, {a[2]:.2f})),")
    surfs = []
    for s, (groups, mat) in B.SURFACES.items():
        g = ", ".join(f'"{x}"' for x in groups)
        surfs.append(f"        (name: \"{s}\", groups: [{g}], material: \"{mat}\"),")
    (out / "scene.ron").write_text(
        "// validation/outdoor: RADIANCE building (issue 31). Targets: the materials with PseudoBrdf;\n"
        "// the environment (ground, neighbour) gives its known diffuse albedo.\n"
        "Scene(\n    name: \"radiance-building\",\n    geometry: \"building.obj\",\n    materials: [\n"
        + "\n".join(mats) + "\n    ],\n    surfaces: [\n" + "\n".join(surfs) + "\n    ],\n)\n"
    )


def write_photos(out, path, width, height, stems, utc):
    cams = [f"        (name: \"{c}\", radiance_view: \"{B.view_string(c, width, height)}\", width: {width}, height: {height}),"
            for c in B.CAMERAS]
    photos = [f"        (camera: \"{c}\", time: \"{utc[s]}\", image: \"views/{c}-{s}.hdr\", mask: Some(\"masks/{c}.png\")),"
              for s in stems for c in B.CAMERAS]
    (out / path).write_text(
        "// validation/outdoor: rpict renders (W·m⁻²·sr⁻¹ per channel); masks: 255 on target surfaces\n"
        "OutdoorPhotos(\n    cameras: [\n" + "\n".join(cams) + "\n    ],\n    photos: [\n" + "\n".join(photos)
        + "\n    ],\n)\n"
    )


def write_light(out, path, entries, fisheye):
    s = B.SITE
    rows = []
    for e in entries:
        sky = (f"Image(image: \"skies/{e['stem']}-fisheye.hdr\", view: \"from-image\")" if fisheye
               else f"File(\"skies/{e['stem']}.ron\")")
        es = e["e_sun"]
        g = e["ground"]
        rows.append(
            "        (\n"
            f"            time: \"{e['utc']}\",\n"
            f"            sun_direction: Some((azimuth_deg: {e['az']!r}, zenith_deg: {e['zen']!r})),\n"
            f"            sun: Irradiance(({es[0]!r}, {es[1]!r}, {es[2]!r})),\n"
            f"            sky: {sky},\n"
            f"            below_horizon: Some(({g[0]!r}, {g[1]!r}, {g[2]!r})),\n"
            "        ),"
        )
    (out / path).write_text(
        "// validation/outdoor: gendaylit's sun (normal irradiance of the 0.533° disc, W/m² per channel)\n"
        "// and sky at each photo time (the held-out time included)\n"
        f"OutdoorLight(\n    site: Some((latitude_deg: {s['latitude_deg']}, longitude_deg: {s['longitude_deg']}, "
        f"elevation_m: {s['elevation_m']})),\n    times: [\n" + "\n".join(rows) + "\n    ],\n)\n"
    )


def truth():
    surfaces = []
    for s, (groups, mat) in B.SURFACES.items():
        e = {"name": s, "groups": groups, "material": mat, "target": mat in B.TARGET_MATERIALS}
        if mat == "brick":
            px = 0.5
            nx, ny = int(B.W / px), int(B.EAVES / px)
            ss = (np.arange(nx) + 0.5) * px
            tt = (np.arange(ny) + 0.5) * px
            idx = B.brick_level(ss[None, :], tt[:, None])
            levels = np.array(B.BRICK_LEVELS)
            e["rho"] = (levels[idx].reshape(-1, 3).mean(0)).round(9).tolist()
            e["texture"] = {
                "origin_m": list(B.BRICK_ORIGIN), "s_axis": list(B.BRICK_S), "t_axis": list(B.BRICK_T),
                "pixel_m": px, "width": nx, "height": ny,
                "levels": [list(l) for l in B.BRICK_LEVELS],
                "index": idx.tolist(),
                "rule": "s = (p - origin)·s_axis, t = (p - origin)·t_axis; rho = levels[index[floor(t / pixel_m)]"
                        "[floor(s / pixel_m)]] (row 0 at t = 0, the bottom), indices clamped to the grid",
            }
        else:
            e["rho"] = list(B.COLOURS[mat])
        surfaces.append(e)
    return {
        "scene": "radiance-building",
        "rule": "RADIANCE plastic with specularity 0: rho = colour × pattern (normal.c: rdiff = 1 - spec = 1, "
                "diffuse radiance = mcolor · rdiff · irradiance / π); no specular term. rho of a textured "
                "surface is its area mean.",
        "surfaces": surfaces,
    }


def target_masks(out, width, height):
    polys = B.polygons()
    targets = {i for i, (_, mat, _) in enumerate(polys) if mat in B.TARGET_MATERIALS}
    stats = {}
    (out / "masks").mkdir(exist_ok=True)
    for c in B.CAMERAS:
        idx, _ = B.trace_groups(c, width, height)
        m = np.isin(idx, list(targets))
        write_png_gray(out / "masks" / f"{c}.png", np.where(m, 255, 0).astype(np.uint8))
        stats[c] = {polys[i][0]: int((idx == i).sum()) for i in sorted(set(idx.ravel().tolist())) if i >= 0}
        stats[c]["sky"] = int((idx < 0).sum())
    return stats


# ---------------------------------------------------------------- rendering


def rpict(env, cwd, octree, view, w, h, extra, out_path):
    cmd = ["rpict"] + view.split() + ["-x", str(w), "-y", str(h)] + COMMON + extra + [octree]
    t = time.perf_counter()
    with open(out_path, "wb") as f:
        p = subprocess.run(cmd, env=env, cwd=cwd, stdout=f, stderr=subprocess.PIPE)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.decode().strip()}")
    return " ".join(cmd[:-1]) + " " + Path(octree).name + " > " + Path(out_path).name, time.perf_counter() - t


def noise(a, b, mask):
    """Per pixel and per 4x4 block: |a - b| / (a + b) over R+G+B (the
    relative difference of one render from the mean of the two is half
    the two renders' difference), on target pixels."""
    sa, sb = a.sum(2), b.sum(2)
    m = mask & (sa + sb > 0)
    pix = np.abs(sa - sb)[m] / (sa + sb)[m]
    h, w = mask.shape
    blocks = []
    for by in range(h // 4):
        for bx in range(w // 4):
            sl = (slice(4 * by, 4 * by + 4), slice(4 * bx, 4 * bx + 4))
            if mask[sl].all():
                x, y = sa[sl].sum(), sb[sl].sum()
                blocks.append(abs(x - y) / (x + y))
    return pix, np.array(blocks)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--fixtures", action="store_true", help="the committed 96x64 set")
    ap.add_argument("--size", default=None, help="WxH (default 96x64 with --fixtures, else 192x128)")
    ap.add_argument("--ab", type=int, default=6)
    ap.add_argument("--ad", type=int, default=1024)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--bounce-study", default="1,2", help="-ab values rendered besides --ab for the bounce study")
    args = ap.parse_args()
    out = Path(args.out).resolve()
    repo = Path(__file__).resolve().parents[2]
    if not args.fixtures and (out == repo or repo in out.parents):
        sys.exit(f"generate.py: the bench set must live outside the repository ({out}); use --fixtures")
    w, h = (96, 64) if args.fixtures and not args.size else (int(x) for x in (args.size or "192x128").split("x"))
    env = radiance_env()
    out.mkdir(parents=True, exist_ok=True)
    for d in ("views", "views-ab0", "skies", "masks"):
        shutil.rmtree(out / d, ignore_errors=True)
        (out / d).mkdir()
    write_rad(out)
    write_obj(out)
    write_scene(out)
    (out / "truth.json").write_text(json.dumps(truth(), indent=1) + "\n")
    pix_stats = target_masks(out, w, h)
    masks = {c: np.asarray(B.trace_groups(c, w, h)[0]) for c in B.CAMERAS}
    polys = B.polygons()
    target_idx = [i for i, (_, mat, _) in enumerate(polys) if mat in B.TARGET_MATERIALS]
    tmask = {c: np.isin(masks[c], target_idx) for c in B.CAMERAS}

    report = {"size": [w, h], "ab": args.ab, "ad": args.ad, "rpict_common": " ".join(COMMON),
              "interreflection": " ".join(interreflection_args(args.ab, args.ad)),
              "pixels_per_group": pix_stats, "times": []}
    entries = []
    jobs = []
    for hour, stem in B.TIMES:
        sky = {ch: gendaylit(env, hour, ch) for ch in CHANNELS}
        sv = sky["g"]["sun_vec"]
        for ch in CHANNELS:
            if sky[ch]["sun_vec"] != sv:
                raise RuntimeError(f"{stem}: gendaylit's sun differs between channels")
        az, zen = sun_angles(sv)
        utc = iso_utc(utc_of_solar(hour))
        e_sun = [round(sky[ch]["sun_radiance"] * SUN_OMEGA, 6) for ch in CHANNELS]
        (out / "skies" / f"{stem}.rad").write_text(sky_rad(sky))
        (out / "skies" / f"{stem}.ron").write_text(sky_file(sky, az, zen))
        with tempfile.TemporaryDirectory() as tmp:
            shutil.copy(out / "sky.cal", tmp)
            check = check_sky(env, sky, tmp)
        with open(out / "skies" / f"{stem}.oct", "wb") as f:
            subprocess.run(["oconv", "building.rad", f"skies/{stem}.rad"], env=env, cwd=out, stdout=f, check=True)
        (out / "skies" / f"{stem}-skyonly.rad").write_text(sky_rad(sky, with_sun=False))
        with open(out / "skies" / f"{stem}-skyonly.oct", "wb") as f:
            subprocess.run(["oconv", f"skies/{stem}-skyonly.rad"], env=env, cwd=out, stdout=f, check=True)
        # The ground glow's brightness A2 per channel: what lies below the
        # horizon beyond the ground plane (Campanile's `below_horizon`).
        ground = [sky[ch]["args"][1] for ch in CHANNELS]
        entries.append(dict(stem=stem, utc=utc, az=round(az, 6), zen=round(zen, 6), e_sun=e_sun, ground=ground))
        report["times"].append({
            "stem": stem, "solar_time_h": hour, "utc": utc, "sun_azimuth_deg": az, "sun_zenith_deg": zen,
            "sun_vector_printed": sv, "e_sun_normal": e_sun, "sky_check_max_rel": check,
            "gendaylit": {ch: {k: sky[ch][k] for k in ("cmd", "stdout", "stderr", "args", "sun_radiance")}
                          for ch in CHANNELS},
        })
        for c in B.CAMERAS:
            view = B.view_string(c, w, h)
            jobs.append((stem, c, view))
    utc = {e["stem"]: e["utc"] for e in entries}
    train = [s for _, s in B.TIMES if s != B.HELDOUT]
    write_photos(out, "photos.ron", w, h, train, utc)
    write_photos(out, "photos-heldout.ron", w, h, [B.HELDOUT], utc)
    write_light(out, "light.ron", entries, fisheye=False)
    write_light(out, "light-fisheye.ron", entries, fisheye=True)

    # Fisheye skies: the sky alone seen from the ridge, -ab 0.
    for e in entries:
        rpict(env, out, f"skies/{e['stem']}-skyonly.oct",
              f"-vta -vp {B.W / 2:g} {B.D / 2:g} {B.RIDGE + 0.01:g} -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180",
              128, 128, ["-ab", "0"], out / "skies" / f"{e['stem']}-fisheye.hdr")

    ambient = interreflection_args(args.ab, args.ad)
    study = [int(x) for x in args.bounce_study.split(",") if x]
    tmpdir = Path(tempfile.mkdtemp(prefix="outdoor-render-"))

    def render(job):
        stem, c, view = job
        oct_ = f"skies/{stem}.oct"
        res = {"stem": stem, "camera": c}
        res["cmd_a"], res["s_a"] = rpict(env, out, oct_, view, w, h, ambient, tmpdir / f"{c}-{stem}-a.hdr")
        res["cmd_b"], res["s_b"] = rpict(env, out, oct_, view, w, h, ambient + ["-u+"], tmpdir / f"{c}-{stem}-b.hdr")
        res["cmd_ab0"], res["s_ab0"] = rpict(env, out, oct_, view, w, h, ["-ab", "0"],
                                             out / "views-ab0" / f"{c}-{stem}.hdr")
        for n in study:
            rpict(env, out, oct_, view, w, h, interreflection_args(n, args.ad), tmpdir / f"{c}-{stem}-ab{n}.hdr")
        return res

    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as ex:
        results = list(ex.map(render, jobs))
    report["render_seconds_wall"] = time.perf_counter() - t0

    all_pix, all_blk, bounce = [], [], {n: [] for n in study}
    per_view = []
    for r in results:
        c, stem = r["camera"], r["stem"]
        a = read_rgbe(tmpdir / f"{c}-{stem}-a.hdr")
        b = read_rgbe(tmpdir / f"{c}-{stem}-b.hdr")
        mean = 0.5 * (a + b)
        write_rgbe(out / "views" / f"{c}-{stem}.hdr", mean, view=B.view_string(c, w, h))
        pix, blk = noise(a, b, tmask[c])
        all_pix.append(pix)
        all_blk.append(blk)
        m = tmask[c]
        row = {"camera": c, "stem": stem, "noise_pixel_median": float(np.median(pix)),
               "noise_block_median": float(np.median(blk)) if len(blk) else None,
               "seconds": [r["s_a"], r["s_b"]]}
        ab0 = read_rgbe(out / "views-ab0" / f"{c}-{stem}.hdr")
        tot = mean.sum(2)[m]
        row["sun_only_fraction"] = float(ab0.sum(2)[m].sum() / tot.sum())
        for n in study:
            x = read_rgbe(tmpdir / f"{c}-{stem}-ab{n}.hdr").sum(2)[m]
            rel = (tot - x) / tot
            bounce[n].append(rel)
            row[f"missing_vs_ab{n}_median"] = float(np.median(rel))
        per_view.append(row)
    cat = np.concatenate
    report["noise"] = {
        "definition": "|a - b| / (a + b) over R+G+B on target pixels: a, b two rpict renders (default seed, -u+); "
                      "each is this far from their mean, the stored image",
        "pixel_median": float(np.median(cat(all_pix))), "pixel_p90": float(np.percentile(cat(all_pix), 90)),
        "block4_median": float(np.median(cat(all_blk))), "block4_p90": float(np.percentile(cat(all_blk), 90)),
        "stored_mean_sigma_note": "the stored mean's own error is about this divided by sqrt(2)",
    }
    report["bounce_study"] = {
        f"ab{args.ab}_minus_ab{n}_over_ab{args.ab}": {
            "median": float(np.median(cat(bounce[n]))), "p90": float(np.percentile(cat(bounce[n]), 90)),
            "max": float(np.max(cat(bounce[n]))),
        } for n in study
    }
    report["views"] = per_view
    report["commands_example"] = {k: results[0][k] for k in ("cmd_a", "cmd_b", "cmd_ab0")}
    (out / "render.json").write_text(json.dumps(report, indent=1) + "\n")
    for f in (out / "skies").glob("*.oct"):
        f.unlink()
    shutil.rmtree(tmpdir, ignore_errors=True)
    print(f"generate.py: {len(results)} views {w}x{h} into {out}; noise per pixel median "
          f"{report['noise']['pixel_median']:.4f}, per 4x4 block {report['noise']['block4_median']:.4f}")


if __name__ == "__main__":
    main()
