#!/usr/bin/env python3
"""Independent ephemeris-to-pixel chain for the sky camera calibration.

For the mis-set all-sky camera of examples/sky-fisheye-sim-station.ron (its
simulation.true_camera), the sun's apparent position from pvlib's NREL SPA
(nrel_numpy), turned into a pixel by this file's own rotation and projection,
written from Campanile's documented conventions (no Campanile code):

- world frame x east, y north, z up; azimuth from north through east;
- the camera on the head at (pan, tilt): azimuth a = pan_zero + pan,
  elevation e = tilt - tilt_zero; forward = (cos e sin a, cos e cos a, sin e),
  right = (cos a, -sin a, 0), down = forward x right; a level-frame vector
  is tilted by the base's roll about north (y), then its pitch about east (x);
- camera frame x right, y down, z forward; the equidistant fisheye images a
  ray theta off the axis at r = theta (1 + k1 theta^2 + k2 theta^4) focal
  lengths from the principal point, along the ray's azimuth about the axis.

Writes fixtures/sun_track.csv: time, pvlib's apparent zenith and azimuth
(degrees), and the pixel (u, v). process/tests/sky_camera_pvlib.rs compares
Campanile's chain (process::sun -> pose::Mount -> pose::Pinhole) with it.

    venv=$(bench/venv.sh pvlib==0.16.1)
    "$venv/bin/python" validation/sky_camera/generate.py
"""
import math
import os
import sys

# The site and true camera of examples/sky-fisheye-sim-station.ron.
SITE = dict(lat=37.8721, lon=-122.2578, elevation_m=90.0, pressure_mbar=1010.0, temperature_c=18.0, delta_t_s=69.2)
CAMERA = dict(focal_px=167.86393, cx=256.0, cy=256.0, k1=0.02, k2=0.0)
MOUNT = dict(pan_zero_deg=3.0, tilt_zero_deg=0.0, roll_deg=1.2, pitch_deg=-0.9)
HEAD = dict(pan_deg=0.0, tilt_deg=90.0)
TIMES = [f"2026-06-21T{h:02d}:{m:02d}:00Z" for h in range(13, 24) for m in (0, 20, 40)] + [
    "2026-06-22T00:00:00Z",
    "2026-06-22T01:00:00Z",
    "2026-06-22T02:00:00Z",
    "2026-06-22T03:00:00Z",
]
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures", "sun_track.csv")


def rot_x(v, a):
    s, c = math.sin(a), math.cos(a)
    return (v[0], c * v[1] - s * v[2], s * v[1] + c * v[2])


def rot_y(v, a):
    s, c = math.sin(a), math.cos(a)
    return (c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def to_camera(w):
    """World direction -> camera frame (the inverse of the documented tilt)."""
    level = rot_y(rot_x(w, -math.radians(MOUNT["pitch_deg"])), -math.radians(MOUNT["roll_deg"]))
    a = math.radians(MOUNT["pan_zero_deg"] + HEAD["pan_deg"])
    e = math.radians(HEAD["tilt_deg"] - MOUNT["tilt_zero_deg"])
    forward = (math.cos(e) * math.sin(a), math.cos(e) * math.cos(a), math.sin(e))
    right = (math.cos(a), -math.sin(a), 0.0)
    down = cross(forward, right)
    return (dot(right, level), dot(down, level), dot(forward, level))


def pixel(c):
    lateral = math.hypot(c[0], c[1])
    theta = math.atan2(lateral, c[2])
    r = theta * (1 + CAMERA["k1"] * theta**2 + CAMERA["k2"] * theta**4)
    ux, uy = (c[0] / lateral, c[1] / lateral) if lateral > 0 else (0.0, 0.0)
    return CAMERA["cx"] + CAMERA["focal_px"] * r * ux, CAMERA["cy"] + CAMERA["focal_px"] * r * uy


def direction(zenith_deg, azimuth_deg):
    z, a = math.radians(zenith_deg), math.radians(azimuth_deg)
    return (math.sin(z) * math.sin(a), math.sin(z) * math.cos(a), math.cos(z))


def self_test():
    """The chain's own known answers, checked on every run."""
    # The zenith, with the base level and north 0, lands on the principal point.
    saved = dict(MOUNT)
    MOUNT.update(pan_zero_deg=0.0, roll_deg=0.0, pitch_deg=0.0)
    u, v = pixel(to_camera((0.0, 0.0, 1.0)))
    assert abs(u - CAMERA["cx"]) < 1e-9 and abs(v - CAMERA["cy"]) < 1e-9, (u, v)
    # East on the horizon: 90 deg off the axis, to the image's right
    # (camera x = east when north is up the image at pan 0, tilt 90).
    u, v = pixel(to_camera((1.0, 0.0, 0.0)))
    want = CAMERA["focal_px"] * (math.pi / 2) * (1 + CAMERA["k1"] * (math.pi / 2) ** 2)
    assert abs(u - CAMERA["cx"] - want) < 1e-9 and abs(v - CAMERA["cy"]) < 1e-9, (u, v, want)
    # North on the horizon is down the image: looking up with east to the
    # right, the camera's down axis (forward x right) points north.
    u, v = pixel(to_camera((0.0, 1.0, 0.0)))
    assert abs(u - CAMERA["cx"]) < 1e-9 and abs(v - CAMERA["cy"] - want) < 1e-9, (u, v)
    MOUNT.clear()
    MOUNT.update(saved)


def main():
    import pandas as pd
    import pvlib

    self_test()
    times = pd.DatetimeIndex(TIMES)
    sp = pvlib.solarposition.get_solarposition(
        times,
        SITE["lat"],
        SITE["lon"],
        altitude=SITE["elevation_m"],
        pressure=SITE["pressure_mbar"] * 100.0,
        temperature=SITE["temperature_c"],
        delta_t=SITE["delta_t_s"],
        method="nrel_numpy",
    )
    rows = ["time,apparent_zenith_deg,azimuth_deg,u_px,v_px"]
    for t, (_, r) in zip(TIMES, sp.iterrows()):
        zen, az = float(r["apparent_zenith"]), float(r["azimuth"])
        if zen >= 90.0:
            continue
        u, v = pixel(to_camera(direction(zen, az)))
        rows.append(f"{t},{zen:.6f},{az:.6f},{u:.5f},{v:.5f}")
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        f.write("\n".join(rows) + "\n")
    print(f"{len(rows) - 1} sun positions (pvlib {pvlib.__version__}) -> {OUT}", file=sys.stderr)


if __name__ == "__main__":
    main()
