"""Independent references for the radiance-image, camera and light readers of
`campanile igi` (issue 24, "Inputs from the renderers and cameras users
have"), made by RADIANCE (pyradiance's binaries) and OpenCV.

    validation/radiance-inputs/make_fixtures.sh   # rewrites fixtures/

Writes into fixtures/:
- pvalue-4x3.hdr / .txt: a 4x3 RGBE picture made by `pvalue -r` then
  `pfilt -1 -e 2` (flat scan lines, EXPOSURE=2), and its pixels as RADIANCE
  reads them back in original units (`pvalue -o`), rows top to bottom.
- sphere.rad, sphere-48x30.hdr, sphere.txt: a bright `light` sphere rendered
  by `rpict` asked for 384x384 with a view whose -vh/-vv aspect is not
  square (rpict shrinks the picture to 384x240, its `normaspect`), box
  filtered 8x8 by `pfilt` to 48x30 (run-length encoded scan lines, VIEW= in
  the header); sphere.txt holds the view and the sphere's centre.
- vwrays-48x30.txt: RADIANCE's ray directions (`vwrays -i`) for pixels of a
  view whose -vh/-vv ratio is not the picture's exactly (rpict's rounding:
  -vh 60 -vv 40 at -x 48 -y 48 gives 48x30).
- light-irradiance.txt: `rtrace -I` irradiance at distances d from a
  `light` sphere of radiance L and radius r, with pi r^2 L / d^2 beside it.
- opencv-4x3.pfm / .txt: a colour PFM written by OpenCV's imwrite, and its
  pixels, rows top to bottom.
"""

import os
import struct
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pyradiance

BIN = Path(pyradiance.__file__).parent / "bin"
LIB = Path(pyradiance.__file__).parent / "lib"
ENV = dict(os.environ, PATH=f"{BIN}:{os.environ['PATH']}", RAYPATH=f".:{LIB}")


def run(args, stdin=None, cwd=None):
    return subprocess.run(args, input=stdin, capture_output=True, check=True, env=ENV, cwd=cwd).stdout


def drop_dates(hdr: bytes) -> bytes:
    """Removes CAPDATE= and GMT= header lines so that reruns give the same bytes."""
    head, sep, rest = hdr.partition(b"\n\n")
    lines = [l for l in head.split(b"\n") if not l.startswith((b"CAPDATE=", b"GMT="))]
    return b"\n".join(lines) + sep + rest


def pvalue_fixture(out: Path):
    vals = []
    for y in range(3):
        for x in range(4):
            i = y * 4 + x
            vals.append((0.25 * (i + 1), 0.5 * (x + 1) + y, 3.0 / (1 + i)))
    raw = b"".join(struct.pack("<3f", *v) for v in vals)
    flat = run(["pvalue", "-r", "-h", "-H", "-df", "-y", "3", "+x", "4"], stdin=raw)
    exposed = run(["pfilt", "-1", "-e", "2"], stdin=flat)
    (out / "pvalue-4x3.hdr").write_bytes(exposed)
    back = run(["pvalue", "-o", "-h", "-H", "-d", str(out / "pvalue-4x3.hdr")]).decode()
    (out / "pvalue-4x3.txt").write_text(
        "# pvalue -o -h -H -d pvalue-4x3.hdr: R G B per pixel in original units, rows top to bottom\n" + back
    )


SPHERE_VIEW = "-vtv -vp 0.2 0.3 0.8 -vd 0.4 1 -0.1 -vu 0 0 1 -vh 60 -vv 39.71"
SPHERE_CENTRE = (1.9, 2.9, 1.2)


def sphere_fixture(out: Path):
    rad = (
        "# A bright sphere seen by a non-square view (validation/radiance-inputs).\n"
        "void light bright\n0\n0\n3 100 60 30\n\n"
        f"bright sphere ball\n0\n0\n4 {SPHERE_CENTRE[0]} {SPHERE_CENTRE[1]} {SPHERE_CENTRE[2]} 0.08\n"
    )
    (out / "sphere.rad").write_text(rad)
    octree = run(["oconv", "sphere.rad"], cwd=out)
    (out / "sphere.oct").write_bytes(octree)
    try:
        big = run(
            ["rpict", *SPHERE_VIEW.split(), "-x", "384", "-y", "384", "-ps", "1", "-pj", "0", "-ab", "0", "sphere.oct"],
            cwd=out,
        )
    finally:
        (out / "sphere.oct").unlink()
    small = run(["pfilt", "-1", "-x", "/8", "-y", "/8"], stdin=big)
    (out / "sphere-48x30.hdr").write_bytes(drop_dates(small))
    (out / "sphere.txt").write_text(
        "# rpict -x 384 -y 384 (made 384x240), pfilt -1 -x /8 -y /8\n"
        f"view {SPHERE_VIEW}\n"
        f"centre {SPHERE_CENTRE[0]} {SPHERE_CENTRE[1]} {SPHERE_CENTRE[2]}\n"
    )


VWRAYS_VIEW = "-vtv -vp 0.2 0.3 0.8 -vd 0.4 1 -0.1 -vu 0 0 1 -vh 60 -vv 40"


def vwrays_fixture(out: Path):
    size = run(["vwrays", "-d", *VWRAYS_VIEW.split(), "-x", "48", "-y", "48"]).decode().split()
    assert size == ["-x", "48", "-y", "30"], size
    pixels = [(0, 0), (47, 29), (10, 5), (40, 20), (23, 14), (0, 29), (47, 0)]
    stdin = "".join(f"{x} {y}\n" for x, y in pixels).encode()
    rays = run(["vwrays", "-i", "-fa", *VWRAYS_VIEW.split(), "-x", "48", "-y", "30"], stdin=stdin).decode().split("\n")
    lines = [
        f"# vwrays -i -fa {VWRAYS_VIEW} -x 48 -y 30 (vwrays -d at -x 48 -y 48 gives {' '.join(size)})",
        "# x y_from_bottom  origin(3) direction(3); the pixel's centre is (x + 0.5, 30 - y - 0.5) from the top-left",
        f"view {VWRAYS_VIEW}",
    ]
    for (x, y), ray in zip(pixels, rays):
        lines.append(f"{x} {y} {ray.strip()}")
    (out / "vwrays-48x30.txt").write_text("\n".join(lines) + "\n")


def light_fixture(out: Path):
    L, r = (20.0, 10.0, 5.0), 0.05
    rad = f"void light lamp\n0\n0\n3 {L[0]} {L[1]} {L[2]}\n\nlamp sphere bulb\n0\n0\n4 0 0 0 {r}\n"
    work = out / "light-tmp"
    work.mkdir(exist_ok=True)
    try:
        (work / "l.rad").write_text(rad)
        (work / "l.oct").write_bytes(run(["oconv", "l.rad"], cwd=work))
        lines = [
            "# rtrace -h -I -ab 0 at (d, 0, 0), normal (-1, 0, 0), facing a RADIANCE light sphere",
            f"# light radiance L = {L[0]} {L[1]} {L[2]} W/m2/sr, sphere radius r = {r} m at the origin",
            "# d_m E_r E_g E_b (W/m2, rtrace) then pi r^2 L_g / d^2",
        ]
        for d in (0.5, 1.0, 2.0):
            e = run(["rtrace", "-h", "-I", "-ab", "0", "l.oct"], stdin=f"{d} 0 0 -1 0 0\n".encode(), cwd=work)
            e = e.decode().split()
            lines.append(f"{d} {' '.join(e)} {np.pi * r * r * L[1] / d / d:.6e}")
        (out / "light-irradiance.txt").write_text("\n".join(lines) + "\n")
    finally:
        for f in work.iterdir():
            f.unlink()
        work.rmdir()


def pfm_fixture(out: Path):
    h, w = 3, 4
    rgb = np.zeros((h, w, 3), np.float32)
    for y in range(h):
        for x in range(w):
            rgb[y, x] = (0.1 * (x + 1) + y, 2.0 ** (x - y), 10.0 * y + x + 0.5)
    # OpenCV takes BGR.
    assert cv2.imwrite(str(out / "opencv-4x3.pfm"), rgb[:, :, ::-1].copy())
    lines = ["# opencv-4x3.pfm (cv2.imwrite): R G B per pixel, rows top to bottom"]
    for y in range(h):
        for x in range(w):
            lines.append(" ".join(f"{v:.9g}" for v in rgb[y, x]))
    (out / "opencv-4x3.txt").write_text("\n".join(lines) + "\n")


def main():
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    pvalue_fixture(out)
    sphere_fixture(out)
    vwrays_fixture(out)
    light_fixture(out)
    pfm_fixture(out)


if __name__ == "__main__":
    main()
