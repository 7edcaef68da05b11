"""Shared pieces of the IGI references (issue 24): box rooms, their faces
and the frames Campanile measures a lobe's orientation in, pinhole views
(RADIANCE's `-vtv` convention, which is also Campanile's), light masks, and
the writers (OBJ, RGBE, EXR, PNG, scene RON, truth JSON).

Nothing here uses Campanile's code: the tangent convention is restated from
the README ("the tangent each gamma is measured from") and checked by
`test_room.py` against the formula written out in README.md.
"""

import json
import math
import struct
import zlib

import numpy as np

# The six faces of a box room [0, W] x [0, D] x [0, H], each a quad whose
# corners run counter-clockwise seen from inside, so the right-handed
# normal (OBJ and RADIANCE polygon convention) points into the room.
FACE_NAMES = ("floor", "ceiling", "wall_south", "wall_north", "wall_west", "wall_east")


def face_corners(name, size):
    w, d, h = size
    return {
        "floor": [(0, 0, 0), (w, 0, 0), (w, d, 0), (0, d, 0)],
        "ceiling": [(0, 0, h), (0, d, h), (w, d, h), (w, 0, h)],
        "wall_south": [(0, 0, 0), (0, 0, h), (w, 0, h), (w, 0, 0)],
        "wall_north": [(0, d, 0), (w, d, 0), (w, d, h), (0, d, h)],
        "wall_west": [(0, 0, 0), (0, d, 0), (0, d, h), (0, 0, h)],
        "wall_east": [(w, 0, 0), (w, 0, h), (w, d, h), (w, d, 0)],
    }[name]


def normal_of(corners):
    a, b, c = (np.array(p, float) for p in corners[:3])
    n = np.cross(b - a, c - a)
    return n / np.linalg.norm(n)


def campanile_tangent_frame(n):
    """The frame Campanile measures gamma in on a face with inward normal n
    (README / process/src/render/mesh.rs texture_axes): t = world up
    projected into the face (north, +y, on horizontal faces), s = t x n the
    tangent (gamma = 0), and the bitangent b = n x s (gamma = +90 deg)."""
    n = np.asarray(n, float)
    t = np.array([0.0, 0.0, 1.0]) - n * n[2]
    if np.linalg.norm(t) < 1e-6:
        t = np.array([0.0, 1.0, 0.0]) - n * n[1]
    t /= np.linalg.norm(t)
    s = np.cross(t, n)
    s /= np.linalg.norm(s)
    b = np.cross(n, s)
    return s, b


def canonical_gamma(alpha_u, alpha_v, u_dir, n):
    """(alpha_x, alpha_y, gamma_deg) in Campanile's canonical form
    (alpha_x >= alpha_y, gamma in (-90, 90]) for a RADIANCE plastic2/metal2
    with u-roughness alpha_u along u_dir projected into the face and
    v-roughness alpha_v along v = n x u (aniso.c getacoords)."""
    n = np.asarray(n, float)
    u = np.asarray(u_dir, float)
    u = u - n * np.dot(n, u)
    u /= np.linalg.norm(u)
    s, b = campanile_tangent_frame(n)
    psi = math.degrees(math.atan2(np.dot(u, b), np.dot(u, s)))
    if alpha_u >= alpha_v:
        ax, ay, g = alpha_u, alpha_v, psi
    else:
        ax, ay, g = alpha_v, alpha_u, psi + 90.0
    while g <= -90.0:
        g += 180.0
    while g > 90.0:
        g -= 180.0
    return ax, ay, g


class View:
    """A perspective view, RADIANCE `-vtv`: right = dir x up, both fields
    of view full angles, pixel (i, j) (column, row from the top) looks
    through image-plane point ((i + .5)/W - .5, .5 - (j + .5)/H)."""

    def __init__(self, name, position, direction, hfov_deg, vfov_deg, width, height, kind):
        self.name = name
        self.position = np.asarray(position, float)
        d = np.asarray(direction, float)
        self.direction = d / np.linalg.norm(d)
        self.hfov_deg = hfov_deg
        self.vfov_deg = vfov_deg
        self.width = width
        self.height = height
        self.kind = kind

    def radiance_args(self):
        p, d = self.position, self.direction
        return (
            f"-vtv -vp {p[0]:.6f} {p[1]:.6f} {p[2]:.6f} -vd {d[0]:.6f} {d[1]:.6f} {d[2]:.6f} "
            f"-vu 0 0 1 -vh {self.hfov_deg:.6f} -vv {self.vfov_deg:.6f}"
        )

    def rays(self):
        """Unit directions, shape (H, W, 3), rows from the top."""
        up = np.array([0.0, 0.0, 1.0])
        right = np.cross(self.direction, up)
        right /= np.linalg.norm(right)
        vup = np.cross(right, self.direction)
        th = math.tan(math.radians(self.hfov_deg) / 2)
        tv = math.tan(math.radians(self.vfov_deg) / 2)
        x = ((np.arange(self.width) + 0.5) / self.width - 0.5) * 2 * th
        y = (0.5 - (np.arange(self.height) + 0.5) / self.height) * 2 * tv
        dirs = self.direction[None, None, :] + x[None, :, None] * right[None, None, :] + y[:, None, None] * vup[None, None, :]
        return dirs / np.linalg.norm(dirs, axis=2, keepdims=True)


def light_mask(view, lights, factor=2.0, dilate=0):
    """255 where the pixel's ray passes farther than factor x radius from
    every light's centre (or behind the camera), 0 where it may see a bulb;
    the zeros grown by `dilate` pixels (for renderers that average over
    the pixel's area instead of tracing its centre)."""
    dirs = view.rays()
    mask = np.full((view.height, view.width), 255, np.uint8)
    for light in lights:
        c = np.asarray(light["position"], float) - view.position
        t = dirs @ c
        dist = np.linalg.norm(dirs * t[..., None] - c, axis=2)
        mask[(t > 0) & (dist < factor * light["radius"])] = 0
    for _ in range(dilate):
        z = mask == 0
        g = z.copy()
        g[1:, :] |= z[:-1, :]
        g[:-1, :] |= z[1:, :]
        g[:, 1:] |= z[:, :-1]
        g[:, :-1] |= z[:, 1:]
        g[1:, 1:] |= z[:-1, :-1]
        g[:-1, :-1] |= z[1:, 1:]
        g[1:, :-1] |= z[:-1, 1:]
        g[:-1, 1:] |= z[1:, :-1]
        mask[g] = 0
    return mask


def write_obj(path, size, faces):
    lines = ["# box room, metres; one group per face; normals point into the room"]
    vid = 1
    for name in faces:
        corners = face_corners(name, size)
        lines.append(f"g {name}")
        for p in corners:
            lines.append("v {:.6f} {:.6f} {:.6f}".format(*p))
        lines.append(f"f {vid} {vid + 1} {vid + 2}")
        lines.append(f"f {vid} {vid + 2} {vid + 3}")
        vid += 4
    path.write_text("\n".join(lines) + "\n")


def write_png_gray(path, img):
    h, w = img.shape
    raw = b"".join(b"\x00" + img[j].tobytes() for j in range(h))

    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    path.write_bytes(png)


def read_rgbe(path):
    """A RADIANCE picture (uncompressed or new-style RLE), standard
    orientation -Y H +X W, as float32 (H, W, 3) with EXPOSURE undone."""
    data = path.read_bytes()
    pos = 0
    exposure = 1.0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("latin-1")
        pos = end + 1
        if line == "":
            break
        if line.startswith("EXPOSURE="):
            exposure *= float(line.split("=")[1])
    end = data.index(b"\n", pos)
    res = data[pos:end].decode().split()
    pos = end + 1
    if res[0] != "-Y" or res[2] != "+X":
        raise ValueError(f"{path}: orientation {' '.join(res)}, expected -Y H +X W")
    h, w = int(res[1]), int(res[3])
    out = np.zeros((h, w, 4), np.uint8)
    for j in range(h):
        if 8 <= w < 32768 and data[pos] == 2 and data[pos + 1] == 2 and data[pos + 2] < 128:
            pos += 4
            for c in range(4):
                i = 0
                while i < w:
                    n = data[pos]
                    pos += 1
                    if n > 128:
                        n -= 128
                        out[j, i : i + n, c] = data[pos]
                        pos += 1
                    else:
                        out[j, i : i + n, c] = np.frombuffer(data[pos : pos + n], np.uint8)
                        pos += n
                    i += n
        else:
            out[j] = np.frombuffer(data[pos : pos + 4 * w], np.uint8).reshape(w, 4)
            pos += 4 * w
    e = out[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(1.0, e - 136), 0.0)
    rgb = (out[..., :3].astype(np.float64) + 0.5) * scale[..., None]
    rgb[e == 0] = 0.0
    return (rgb / exposure).astype(np.float32)


def write_rgbe(path, rgb):
    """Flat (uncompressed) RGBE with the standard header."""
    h, w, _ = rgb.shape
    m = rgb.max(axis=2).astype(np.float64)
    out = np.zeros((h, w, 4), np.uint8)
    ok = m > 1e-32
    mant, ex = np.frexp(m[ok])
    scale = mant * 256.0 / m[ok]
    out[ok, :3] = np.clip(np.floor(rgb[ok] * scale[:, None]), 0, 255).astype(np.uint8)
    out[ok, 3] = (ex + 128).astype(np.uint8)
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n".encode()
    path.write_bytes(header + out.tobytes())


def write_exr(path, rgb, half=False):
    """ZIP-compressed RGB OpenEXR, float32 (or half with `half`)."""
    import OpenEXR

    rgb = np.ascontiguousarray(rgb, np.float16 if half else np.float32)
    channels = {"R": rgb[..., 0].copy(), "G": rgb[..., 1].copy(), "B": rgb[..., 2].copy()}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(str(path))


def exr_scene_ron(views, lights, header, fov_key="hfov_deg", radius=None):
    """A Campanile scene file over room.obj and views/<view>.exr with
    masks/<view>.png: `header` are extra top-level lines (ward_variant,
    interreflection), cameras give `fov_key` (hfov_deg or vfov_deg),
    lights are `Known` points of their intensity with their radius, or
    `radius` when given."""
    lines = ["IgiScene(", '    geometry: "room.obj",', "    surfaces: [],"] + header + ["    cameras: ["]
    for v in views:
        fov = v.hfov_deg if fov_key == "hfov_deg" else v.vfov_deg
        lines.append(
            f'        (name: "{v.name}", position_m: {ron_tuple(v.position)}, look: {ron_tuple(v.direction)}, '
            f"up: (0.0, 0.0, 1.0), {fov_key}: {fov:.6f}, width: {v.width}, height: {v.height}),"
        )
    lines += ["    ],", "    lights: ["]
    for light in lights:
        r = light["radius"] if radius is None else radius
        lines.append(
            f'        Known(name: "{light["name"]}", position_m: {ron_tuple(light["position"])}, '
            f'radius_m: {r}, intensity_w_sr: {ron_tuple(light["intensity"])}),'
        )
    lines += ["    ],", "    images: ["]
    for v in views:
        lines.append(f'        (camera: "{v.name}", image: "views/{v.name}.exr", mask: Some("masks/{v.name}.png")),')
    lines += ["    ],", ")"]
    return "\n".join(lines) + "\n"


def ron_tuple(v, fmt="{:.6f}"):
    return "(" + ", ".join(fmt.format(x) for x in v) + ")"


def write_json(path, obj):
    path.write_text(json.dumps(obj, indent=2, sort_keys=False) + "\n")
