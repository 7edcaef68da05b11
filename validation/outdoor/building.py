"""The RADIANCE building of issue 31: geometry, materials, the brick
pattern, the cameras and the day. Frame: x east, y north, z up, metres.
Nothing here runs RADIANCE; generate.py writes and renders it."""

import math

import numpy as np

# ---------------------------------------------------------------- site and day

SITE = dict(latitude_deg=37.87, longitude_deg=-122.26, elevation_m=60.0)
# gendaylit's site arguments: -a latitude (north), -o longitude (degrees WEST),
# -m standard meridian (degrees west; Pacific Standard Time, UTC-8).
MERIDIAN_WEST_DEG = 120.0
UTC_OFFSET_H = -8.0
DATE = (2026, 6, 21)
# Local solar times (hours) and the file stem of each.
TIMES = [(7.0, "0700"), (9.5, "0930"), (12.0, "1200"), (14.5, "1430"), (17.0, "1700")]
HELDOUT = "1430"

# Per-channel Perez clearness and brightness (validation/sky's "Denver" clear
# sky: green in bin 8, red clearer, blue hazier; Δ_r = 0.85 Δ, Δ_b = 1.15 Δ).
EPS = {"r": 7.475, "g": 6.5, "b": 6.78}
DELTA = {"r": 0.102, "g": 0.12, "b": 0.138}

# ---------------------------------------------------------------- materials

# Diffuse reflectances (RADIANCE `plastic` colour, spec 0, roughness 0).
PLASTER = (0.62, 0.58, 0.50)
TILES = (0.42, 0.24, 0.18)
GROUND = (0.20, 0.19, 0.17)
NEIGHBOUR = (0.35, 0.33, 0.30)
# The brick wall: colour (1, 1, 1) times a `colorfunc` pattern of three levels.
BRICK_LEVELS = [(0.46, 0.25, 0.17), (0.33, 0.18, 0.13), (0.58, 0.40, 0.30)]
BRICK_W = 2.0  # block width (m), along s
BRICK_H = 1.0  # course height (m), along t; odd courses offset by 1 m

# ---------------------------------------------------------------- geometry

W, D, EAVES, RIDGE = 10.0, 6.0, 5.0, 7.0
NB = dict(x0=14.0, x1=20.0, y0=-1.0, y1=7.0, h=6.0)
GROUND_HALF = 100.0  # the ground square spans ±100 m around the building


def _building():
    m = D / 2
    return [
        # (group, material, corners: counter-clockwise seen from outside)
        ("south-wall", "brick", [(0, 0, 0), (W, 0, 0), (W, 0, EAVES), (0, 0, EAVES)]),
        ("east-wall", "plaster", [(W, 0, 0), (W, D, 0), (W, D, EAVES), (W, m, RIDGE), (W, 0, EAVES)]),
        ("north-wall", "plaster", [(W, D, 0), (0, D, 0), (0, D, EAVES), (W, D, EAVES)]),
        ("west-wall", "plaster", [(0, D, 0), (0, 0, 0), (0, 0, EAVES), (0, m, RIDGE), (0, D, EAVES)]),
        ("roof-south", "tiles", [(0, 0, EAVES), (W, 0, EAVES), (W, m, RIDGE), (0, m, RIDGE)]),
        ("roof-north", "tiles", [(W, D, EAVES), (0, D, EAVES), (0, m, RIDGE), (W, m, RIDGE)]),
    ]


def _box(prefix, x0, x1, y0, y1, h):
    return [
        (f"{prefix}-south", [(x0, y0, 0), (x1, y0, 0), (x1, y0, h), (x0, y0, h)]),
        (f"{prefix}-east", [(x1, y0, 0), (x1, y1, 0), (x1, y1, h), (x1, y0, h)]),
        (f"{prefix}-north", [(x1, y1, 0), (x0, y1, 0), (x0, y1, h), (x1, y1, h)]),
        (f"{prefix}-west", [(x0, y1, 0), (x0, y0, 0), (x0, y0, h), (x0, y1, h)]),
        (f"{prefix}-roof", [(x0, y0, h), (x1, y0, h), (x1, y1, h), (x0, y1, h)]),
    ]


def polygons():
    """Every polygon: (group, material, corners), outward normals."""
    out = list(_building())
    out += [(g, "neighbour", c) for g, c in _box("neighbour", NB["x0"], NB["x1"], NB["y0"], NB["y1"], NB["h"])]
    g = GROUND_HALF
    cx, cy = W / 2, D / 2
    out.append(("ground", "ground", [(cx - g, cy - g, 0), (cx + g, cy - g, 0), (cx + g, cy + g, 0), (cx - g, cy + g, 0)]))
    return out


def normal_of(corners):
    """Newell's normal of a planar polygon, unit length."""
    p = np.asarray(corners, float)
    n = np.zeros(3)
    for i in range(len(p)):
        a, b = p[i], p[(i + 1) % len(p)]
        n += np.array([(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1])])
    return n / np.linalg.norm(n)


# Campanile surfaces: name -> (groups, material).
SURFACES = {
    "south-wall": (["south-wall"], "brick"),
    "east-wall": (["east-wall"], "plaster"),
    "north-wall": (["north-wall"], "plaster"),
    "west-wall": (["west-wall"], "plaster"),
    "roof": (["roof-south", "roof-north"], "tiles"),
    "neighbour": ([f"neighbour-{s}" for s in ("south", "east", "north", "west", "roof")], "neighbour"),
    "ground": (["ground"], "ground"),
}
TARGET_MATERIALS = ["brick", "plaster", "tiles"]
KNOWN_ALBEDO = {"ground": GROUND, "neighbour": NEIGHBOUR}
COLOURS = {"plaster": PLASTER, "tiles": TILES, "ground": GROUND, "neighbour": NEIGHBOUR, "brick": (1.0, 1.0, 1.0)}

# ---------------------------------------------------------------- brick pattern

# The pattern's frame on the south wall (normal -y): s along +x from the
# west corner, t up from the ground.
BRICK_ORIGIN = (0.0, 0.0, 0.0)
BRICK_S = (1.0, 0.0, 0.0)
BRICK_T = (0.0, 0.0, 1.0)


def brick_level(s, t):
    """Index into BRICK_LEVELS at (s, t) metres (numpy arrays or floats):
    course j = floor(t / H); odd courses shifted by half a block; block i =
    floor((s + (j mod 2) * W / 2) / W); level (i + 2 j) mod 3."""
    j = np.floor(np.asarray(t, float) / BRICK_H)
    shift = np.mod(j, 2) * BRICK_W / 2
    i = np.floor((np.asarray(s, float) + shift) / BRICK_W)
    return np.mod(i + 2 * j, 3).astype(int)


BRICK_CAL = """{ validation/outdoor: the south wall's brick pattern, written for this test.
  s = Px (m, east), t = Pz (m, up); courses 1 m high, blocks 2 m wide,
  odd courses shifted by 1 m; level (block + 2 course) mod 3. }
b_row = floor(Pz / %(h)r);
b_col = floor((Px + (b_row - 2 * floor(b_row / 2)) * %(half)r) / %(w)r);
b_lev = (b_col + 2 * b_row) - 3 * floor((b_col + 2 * b_row) / 3);
b_pick(c0, c1, c2) = if(b_lev - 1.5, c2, if(b_lev - .5, c1, c0));
brick_r = b_pick(%(r0)r, %(r1)r, %(r2)r);
brick_g = b_pick(%(g0)r, %(g1)r, %(g2)r);
brick_b = b_pick(%(b0)r, %(b1)r, %(b2)r);
""" % dict(
    h=BRICK_H, w=BRICK_W, half=BRICK_W / 2,
    r0=BRICK_LEVELS[0][0], r1=BRICK_LEVELS[1][0], r2=BRICK_LEVELS[2][0],
    g0=BRICK_LEVELS[0][1], g1=BRICK_LEVELS[1][1], g2=BRICK_LEVELS[2][1],
    b0=BRICK_LEVELS[0][2], b1=BRICK_LEVELS[1][2], b2=BRICK_LEVELS[2][2],
)

# The sky: gendaylit's perezlum.cal evaluated per channel (our own
# expressions of the formula in perezlum.cal; arguments 1-10 red, 11-20
# green, 21-30 blue, each as gendaylit prints them: diffuse normalization,
# ground brightness, Perez a..e, sun x y z).
SKY_CAL = """{ validation/outdoor: gendaylit's per-channel Perez sky (the formula of
  RADIANCE's perezlum.cal, written here for three channels at once).
  Arguments 10 k + 1 .. 10 k + 10 (k = 0 red, 1 green, 2 blue): A1 diffuse
  normalization, A2 ground brightness, A3..A7 Perez a..e, A8..A10 sun. }
p_cg(k) = Dx * arg(k + 8) + Dy * arg(k + 9) + Dz * arg(k + 10);
p_dz = if(Dz - 0.01, Dz, 0.01);
p_inter(k) = arg(k + 1) * (1 + arg(k + 3) * Exp(arg(k + 4) / p_dz))
        * (1 + arg(k + 5) * Exp(arg(k + 6) * Acos(p_cg(k))) + arg(k + 7) * p_cg(k) * p_cg(k));
p_wa = (Dz + 1.01) ^ 10;
p_wb = (Dz + 1.01) ^ -10;
p_sky(k) = (p_wa * p_inter(k) + p_wb * arg(k + 2)) / (p_wa + p_wb);
sky_r = p_sky(0);
sky_g = p_sky(10);
sky_b = p_sky(20);
"""

# ---------------------------------------------------------------- cameras

HFOV = 60.0


def vfov(width, height, hfov=HFOV):
    return 2 * math.degrees(math.atan(math.tan(math.radians(hfov) / 2) * height / width))


# name -> (position, point looked at)
CAMERAS = {
    "south-west": ((-7.0, -11.0, 1.6), (5.0, 3.0, 3.0)),
    "south-east": ((17.0, -12.0, 1.6), (7.0, 3.0, 3.0)),
    "north-east": ((17.0, 14.0, 1.6), (7.0, 3.0, 3.0)),
    "north-west": ((-8.0, 15.0, 1.6), (5.0, 3.0, 3.0)),
}


def view_string(name, width, height):
    p, t = CAMERAS[name]
    d = np.subtract(t, p)
    d = d / np.linalg.norm(d)
    return (
        f"-vtv -vp {p[0]:g} {p[1]:g} {p[2]:g} -vd {d[0]:.6f} {d[1]:.6f} {d[2]:.6f} -vu 0 0 1 "
        f"-vh {HFOV:g} -vv {vfov(width, height):.6f}"
    )


def rays(name, width, height):
    """Unit directions (H, W, 3) through the pixel centres, rows from the
    top, as rpict -vtv traces them (-pa 0 -pj 0 -ps 1)."""
    p, t = CAMERAS[name]
    d = np.subtract(t, p)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0])
    right = np.cross(d, up)
    right /= np.linalg.norm(right)
    vup = np.cross(right, d)
    th = math.tan(math.radians(HFOV) / 2)
    tv = math.tan(math.radians(vfov(width, height)) / 2)
    x = ((np.arange(width) + 0.5) / width - 0.5) * 2 * th
    y = (0.5 - (np.arange(height) + 0.5) / height) * 2 * tv
    r = d[None, None, :] + x[None, :, None] * right[None, None, :] + y[:, None, None] * vup[None, None, :]
    return np.asarray(p, float), r / np.linalg.norm(r, axis=2, keepdims=True)


def trace_groups(name, width, height):
    """For each pixel, the index into polygons() of the first polygon hit
    (-1: sky), and the hit points (H, W, 3)."""
    origin, dirs = rays(name, width, height)
    polys = polygons()
    best_t = np.full(dirs.shape[:2], np.inf)
    best_i = np.full(dirs.shape[:2], -1)
    for k, (_, _, corners) in enumerate(polys):
        c = np.asarray(corners, float)
        n = normal_of(c)
        denom = dirs @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((c[0] - origin) @ n) / denom
        hit = origin + dirs * t[..., None]
        inside = np.ones(t.shape, bool)
        for a in range(len(c)):
            e = c[(a + 1) % len(c)] - c[a]
            inside &= np.einsum("ijk,k->ij", np.cross(e, hit - c[a]), n) >= -1e-9
        ok = inside & (t > 1e-6) & (t < best_t) & np.isfinite(t)
        best_t[ok] = t[ok]
        best_i[ok] = k
    return best_i, origin + dirs * np.where(np.isfinite(best_t), best_t, 0)[..., None]
