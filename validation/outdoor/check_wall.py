"""Hand arithmetic on the rendered images: the west wall, sunlit and open to
the west (nothing of the scene in front of it but the ground), against
L = rho (E_sun cos θ + E_sky + E_ground) / π from the light files alone.

    python check_wall.py DIR [--time 1700] [--camera south-west]

E_sky: eq. 5.9 with perezlum.cal's horizon blend (exactly what rtrace
renders, 5e-7) integrated over the quarter sphere the wall sees (upper
hemisphere, d·n > 0), 0.1° steps. E_ground: the ground below the horizon
seen by the wall (view factor 1/2) at the radiance of an unoccluded
Lambertian ground, rho_g (E_sun cos θz + E_sky,h) / π, once reflected
(higher orders and the ground's occlusion by the building left out).
"""

import argparse
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import building as B  # noqa: E402
from rgbe import read_rgbe  # noqa: E402


def sky_models(path):
    text = Path(path).read_text()
    out = {}
    for ch, body in re.findall(r'channel: "(\w)", model: \(([^)]*)\)', text):
        out[ch] = {k: float(v) for k, v in re.findall(r"(\w+): ([-0-9.e+]+)", body)}
    return out


def integrate(models, ground_args, sun, n, step_deg=0.1):
    """Irradiance (per channel) on a plane of normal n from the sky
    (eq. 5.9 blended toward the ground brightness near the horizon as
    perezlum.cal does) over the upper hemisphere."""
    zs = np.radians(np.arange(step_deg / 2, 90, step_deg))
    az = np.radians(np.arange(step_deg / 2, 360, step_deg))
    Z, A = np.meshgrid(zs, az, indexing="ij")
    d = np.stack([np.sin(Z) * np.sin(A), np.sin(Z) * np.cos(A), np.cos(Z)], -1)
    dw = np.sin(Z) * math.radians(step_deg) ** 2
    cosn = np.maximum(d @ n, 0)
    cg = np.clip(d @ sun, -1, 1)
    cz = np.maximum(d[..., 2], 0.01)
    wa, wb = (d[..., 2] + 1.01) ** 10, (d[..., 2] + 1.01) ** -10
    out = []
    for ch in "rgb":
        m = models[ch]
        L = m["lz"] * (1 + m["a"] * np.exp(m["b"] / cz)) * (1 + m["c"] * np.exp(m["d"] * np.arccos(cg)) + m["e"] * cg * cg)
        L = (wa * L + wb * ground_args[ch]) / (wa + wb)
        out.append(float((L * cosn * dw).sum()))
    return np.array(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--time", default="1700")
    ap.add_argument("--camera", default="south-west")
    a = ap.parse_args()
    d = Path(a.dir)
    rep = json.loads((d / "render.json").read_text())
    t = next(x for x in rep["times"] if x["stem"] == a.time)
    sun = np.asarray(t["sun_vector_printed"])
    e_sun = np.asarray(t["e_sun_normal"])
    models = sky_models(d / "skies" / f"{a.time}.ron")
    ground_args = {ch: t["gendaylit"][ch]["args"][1] for ch in "rgb"}
    n = np.array([-1.0, 0.0, 0.0])
    e_direct = e_sun * max(0.0, float(sun @ n))
    e_sky = integrate(models, ground_args, sun, n)
    e_sky_h = integrate(models, ground_args, sun, np.array([0.0, 0.0, 1.0]))
    e_h = e_sun * sun[2] + e_sky_h
    L_ground = np.asarray(B.GROUND) * e_h / math.pi
    e_ground = math.pi * L_ground * 0.5
    rho = np.asarray(B.PLASTER)
    L_pred = rho * (e_direct + e_sky + e_ground) / math.pi
    w, h = rep["size"]
    img = read_rgbe(d / "views" / f"{a.camera}-{a.time}.hdr")
    idx, pts = B.trace_groups(a.camera, w, h)
    k = [i for i, p in enumerate(B.polygons()) if p[0] == "west-wall"][0]
    sel = (idx == k) & (pts[..., 2] > 1.0) & (pts[..., 2] < 4.0) & (pts[..., 1] > 1.0) & (pts[..., 1] < 5.0)
    L_img = img[sel].mean(0)
    print(f"{a.camera} {a.time}: west wall, {int(sel.sum())} pixels (1 < y < 5 m, 1 < z < 4 m); rho = {rho.tolist()}")
    for name, v in (("E_sun cos θ", e_direct), ("E_sky (wall)", e_sky), ("E_ground, one bounce", e_ground),
                    ("E_horizontal (sun + sky)", e_h)):
        print(f"  {name:<26} {v[0]:8.2f} {v[1]:8.2f} {v[2]:8.2f} W/m²")
    print(f"  L predicted                {L_pred[0]:8.3f} {L_pred[1]:8.3f} {L_pred[2]:8.3f} W/m²/sr")
    print(f"  L rendered (mean)          {L_img[0]:8.3f} {L_img[1]:8.3f} {L_img[2]:8.3f} W/m²/sr")
    print(f"  rendered / predicted       {L_img[0] / L_pred[0]:8.4f} {L_img[1] / L_pred[1]:8.4f} {L_img[2] / L_pred[2]:8.4f}")


if __name__ == "__main__":
    main()
