#!/usr/bin/env python3
"""Camera pose from targets (thesis §3.3): OpenCV's solvePnP on fixed
correspondences, the independent reference for `process::registration`.

Each case is a camera (focal length, principal point, radial k1 and k2), a
true pose, and square targets (four corners each) at surveyed world points;
the corners are projected by OpenCV's own `projectPoints` with the same lens
and then given seeded Gaussian pixel noise. OpenCV's `solvePnP`
(SOLVEPNP_ITERATIVE: its Levenberg-Marquardt on the reprojection error,
started from SOLVEPNP_SQPNP) gives the reference pose. Campanile's test
(`process/tests/registration_opencv.rs`) registers the same pixels and must
land on the same pose.

    venv=$(bench/venv.sh opencv-python-headless numpy)
    "$venv/bin/python" validation/registration/generate.py          # rewrite the fixture
    "$venv/bin/python" validation/registration/generate.py --check  # compare with the committed one

Deterministic: the same numbers on every run (numpy's PCG64 with fixed seeds).
"""
import json
import math
import sys
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
FIXTURE = HERE / "fixtures" / "pnp-cases.json"


def look_at(centre, target, roll_deg):
    """World-to-camera rotation (rows: right, down, forward) of a camera at
    `centre` looking at `target`, rolled `roll_deg` about its axis."""
    f = np.asarray(target, float) - np.asarray(centre, float)
    f /= np.linalg.norm(f)
    r = np.cross(f, [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    d = np.cross(f, r)
    a = math.radians(roll_deg)
    r2 = r * math.cos(a) + d * math.sin(a)
    d2 = np.cross(f, r2)
    return np.vstack([r2, d2, f])


def square_corners(centre, normal, size):
    """Corners top-left, top-right, bottom-right, bottom-left of a square
    facing `normal` with its top toward world up (north if horizontal)."""
    n = np.asarray(normal, float)
    n /= np.linalg.norm(n)
    up = np.array([0.0, 0.0, 1.0]) - n * n[2]
    if np.linalg.norm(up) < 1e-6:
        up = np.array([0.0, 1.0, 0.0]) - n * n[1]
    up /= np.linalg.norm(up)
    right = np.cross(up, n)
    h = size / 2
    c = np.asarray(centre, float)
    return [c + h * (a * right + b * up) for a, b in [(-1, 1), (1, 1), (1, -1), (-1, -1)]]


CASES = [
    # name, focal, principal, k1, k2, centre, look at, roll, noise px, targets (centre, normal, size)
    ("building-corner-14m", 1385.6, (800.0, 600.0), -0.05, 0.01, (13.0, -15.0, 1.6), (3.0, -3.0, 3.0), 4.0, 0.3,
     [((x, -5.502, z), (0, -1, 0), 0.6) for x, z in [(-4, 1.2), (-1.5, 1.0), (1.5, 1.4), (4, 1.1), (2.5, 5.0), (0, 7.5)]]
     + [((5.502, y, z), (1, 0, 0), 0.6) for y, z in [(-4, 1.3), (-1, 1.0), (2, 1.2), (-2.5, 4.0)]]),
    ("wall-10m-planar", 1385.6, (800.0, 600.0), -0.05, 0.01, (0.5, -15.5, 1.5), (0.0, -5.5, 3.5), -2.0, 0.2,
     [((x, -5.502, z), (0, -1, 0), 0.6) for x, z in [(-4, 1.2), (-1.5, 1.0), (1.5, 1.4), (4, 1.1), (-3, 4.5), (2.5, 5.0), (0, 7.5)]]),
    ("room-3m-strong-distortion", 900.0, (640.0, 480.0), -0.18, 0.04, (3.8, 0.6, 1.5), (0.5, 3.5, 1.5), 8.0, 0.3,
     [((x, 3.998, z), (0, -1, 0), 0.2) for x, z in [(0.5, 1.5), (2.5, 1.6), (4.5, 1.4), (1.5, 2.7), (3.5, 0.8)]]
     + [((0.002, y, z), (1, 0, 0), 0.2) for y, z in [(2.6, 1.5), (3.4, 2.2), (1.4, 0.6), (0.4, 2.0)]]),
]


def make_case(k, case):
    name, f, (cx, cy), k1, k2, centre, at, roll, noise, targets = case
    rot = look_at(centre, at, roll)
    c = np.asarray(centre, float)
    rvec, _ = cv2.Rodrigues(rot)
    tvec = -rot @ c
    K = np.array([[f, 0, cx], [0, f, cy], [0, 0, 1]], float)
    dist = np.array([k1, k2, 0.0, 0.0, 0.0])
    world, ids = [], []
    for i, (tc, tn, ts) in enumerate(targets):
        for corner in square_corners(tc, tn, ts):
            world.append(corner)
            ids.append(i)
    world = np.asarray(world, float)
    pix, _ = cv2.projectPoints(world, rvec, tvec, K, dist)
    pix = pix.reshape(-1, 2)
    rng = np.random.default_rng(1000 + k)
    pix = pix + rng.normal(0.0, noise, pix.shape)
    ok, r0, t0 = cv2.solvePnP(world, pix, K, dist, flags=cv2.SOLVEPNP_SQPNP)
    ok2, r1, t1 = cv2.solvePnP(world, pix, K, dist, rvec=r0, tvec=t0, useExtrinsicGuess=True,
                               flags=cv2.SOLVEPNP_ITERATIVE)
    assert ok and ok2
    R1, _ = cv2.Rodrigues(r1)
    centre_cv = (-R1.T @ t1).ravel()
    reproj, _ = cv2.projectPoints(world, r1, t1, K, dist)
    rms = float(np.sqrt(np.mean(np.sum((reproj.reshape(-1, 2) - pix) ** 2, axis=1))))
    r6 = lambda v: [round(float(x), 10) for x in v]
    return {
        "name": name,
        "focal_px": f, "principal_px": [cx, cy], "k1": k1, "k2": k2,
        "noise_px": noise,
        "points": [{"target": int(i), "pixel": r6(p), "world": r6(w)} for i, p, w in zip(ids, pix, world)],
        "true_centre_m": r6(c), "true_rotation": [r6(row) for row in rot],
        "opencv_centre_m": r6(centre_cv), "opencv_rotation": [r6(row) for row in R1],
        "opencv_rms_px": round(rms, 10),
    }


def main():
    doc = {
        "generator": "validation/registration/generate.py",
        "opencv": cv2.__version__,
        "numpy": np.__version__,
        "cases": [make_case(k, c) for k, c in enumerate(CASES)],
    }
    text = json.dumps(doc, indent=1) + "\n"
    if "--check" in sys.argv:
        old = json.loads(FIXTURE.read_text())
        new = json.loads(text)
        for a, b in zip(old["cases"], new["cases"]):
            for key in ("opencv_centre_m",):
                d = max(abs(x - y) for x, y in zip(a[key], b[key]))
                assert d < 1e-8, f"{a['name']}: {key} moved by {d}"
        print(f"fixture reproduced ({len(new['cases'])} cases)")
        return
    FIXTURE.write_text(text)
    for c in doc["cases"]:
        err = np.linalg.norm(np.subtract(c["opencv_centre_m"], c["true_centre_m"]))
        print(f"{c['name']}: OpenCV centre {err * 1e3:.2f} mm from the truth, rms {c['opencv_rms_px']:.3f} px")


if __name__ == "__main__":
    main()
