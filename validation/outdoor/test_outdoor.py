"""Checks of what generate.py wrote (run by generate.sh): the truth's grid
against the pattern RADIANCE rendered, the sky files and the sun against
gendaylit's printed numbers, every path the RON files name, the masks.

    python test_outdoor.py DIR     # exit 1 on the first failed check
"""

import json
import math
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import building as B  # noqa: E402
import compare as C  # noqa: E402
from rgbe import read_rgbe  # noqa: E402

SUN_OMEGA = 2 * math.pi * (1 - math.cos(math.radians(0.2665)))


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        sys.exit(1)


def main():
    d = Path(sys.argv[1])
    truth = json.loads((d / "truth.json").read_text())
    brick = next(s for s in truth["surfaces"] if s["name"] == "south-wall")
    rng = np.random.default_rng(7)
    pts = np.column_stack([rng.uniform(0, B.W, 5000), np.zeros(5000), rng.uniform(0, B.EAVES, 5000)])
    want = np.asarray(B.BRICK_LEVELS)[B.brick_level(pts[:, 0], pts[:, 2])]
    got = C.truth_at(brick, pts)
    check(np.array_equal(want, got), "truth.json's brick grid = brick.cal's rule at 5000 random points")
    rep = json.loads((d / "render.json").read_text())
    light = (d / "light.ron").read_text()
    for t in rep["times"]:
        sky = (d / "skies" / f"{t['stem']}.ron").read_text()
        for ch in "rgb":
            args = t["gendaylit"][ch]["args"]
            m = re.search(rf'channel: "{ch}", model: \(lz: ([^,]+), a: ([^,]+), b: ([^,]+), c: ([^,]+), '
                          rf'd: ([^,]+), e: ([^,]+), h: 1.0\)', sky)
            vals = [float(x) for x in m.groups()]
            check(vals == [args[0]] + args[2:7], f"{t['stem']} {ch}: SkyFile (lz, a..e) = gendaylit's (A1, A3..A7)")
        e = [float(x) for x in re.search(rf'time: "{t["utc"]}",\s*sun_direction: Some\(\(azimuth_deg: [^,]+, '
                                         rf'zenith_deg: [^)]+\)\),\s*sun: Irradiance\(\(([^)]*)\)\)', light)
             .group(1).split(",")]
        want_e = [t["gendaylit"][ch]["sun_radiance"] * SUN_OMEGA for ch in "rgb"]
        check(max(abs(a / b - 1) for a, b in zip(e, want_e)) < 1e-6,
              f"{t['stem']}: light.ron's sun = printed radiance x 2pi(1 - cos 0.2665 deg)")
        v = t["sun_vector_printed"]
        az = math.degrees(math.atan2(v[0], v[1])) % 360
        check(abs(az - t["sun_azimuth_deg"]) < 1e-9 and abs(math.degrees(math.acos(v[2])) - t["sun_zenith_deg"]) < 1e-9,
              f"{t['stem']}: sun azimuth/zenith from gendaylit's vector")
        check(t["sky_check_max_rel"]["sky_cal_vs_perezlum_cal_green"] < 1e-6,
              f"{t['stem']}: sky.cal renders perezlum.cal's green sky "
              f"({t['sky_check_max_rel']['sky_cal_vs_perezlum_cal_green']:.1e})")
    for ron in ("photos.ron", "photos-heldout.ron", "light.ron", "light-fisheye.ron", "scene.ron"):
        for p in re.findall(r'(?:image|geometry): "([^"]+)"|File\("([^"]+)"\)|Some\("([^"]+)"\)', (d / ron).read_text()):
            p = next(x for x in p if x)
            check((d / p).exists(), f"{ron}: {p} exists")
    w, h = rep["size"]
    for c in B.CAMERAS:
        m = C.read_png_gray(d / "masks" / f"{c}.png") > 0
        img = read_rgbe(d / "views" / f"{c}-1200.hdr")
        check(m.shape == (h, w) and m.sum() > 1000 and bool((img[m] > 0).all()),
              f"mask {c}: {int(m.sum())} target pixels, all lit in the noon render")


if __name__ == "__main__":
    main()
