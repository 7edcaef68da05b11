"""RGBE (RADIANCE picture) reading and writing and 8-bit grey PNG writing,
numpy only (the same code as validation/igi/room.py)."""

import struct
import zlib

import numpy as np


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


def write_rgbe(path, rgb, view=None):
    """Flat (uncompressed) RGBE with the standard header (and a VIEW= line)."""
    h, w, _ = rgb.shape
    m = rgb.max(axis=2).astype(np.float64)
    out = np.zeros((h, w, 4), np.uint8)
    ok = m > 1e-32
    mant, ex = np.frexp(m[ok])
    scale = mant * 256.0 / m[ok]
    out[ok, :3] = np.clip(np.floor(rgb[ok] * scale[:, None]), 0, 255).astype(np.uint8)
    out[ok, 3] = (ex + 128).astype(np.uint8)
    view_line = f"VIEW= {view}\n" if view else ""
    header = f"#?RADIANCE\n{view_line}FORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n".encode()
    path.write_bytes(header + out.tobytes())
