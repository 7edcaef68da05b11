"""Scores `campanile outdoor recover` and `outdoor render` against the
RADIANCE building (issue 31).

    python compare.py OUT truth.json [--status ok]       # pseudo-albedos (bound: median <= 2 %)
    python compare.py --render RENDER HELDOUT [--mask M]  # held-out re-render (bound: 4x4 blocks <= 3 %)

Pseudo-albedos: OUT/cells.csv (cell, surface, status, x, y, z, nx, ny, nz,
area_m2, rho_sun_r..b, rho_se_r..b) and OUT/cell_points.csv (cell, x, y, z:
points spread over each cell). The truth of a cell is the mean of the
truth's reflectance at its points (the brick wall's pattern evaluated at
each point; a constant elsewhere). Errors are |rho - truth| / truth.

Render: RENDER (.exr, .hdr, .pfm) against HELDOUT (the RADIANCE render)
over the target pixels (MASK: 8-bit PNG, non-zero = use; by default
masks/<camera>.png beside HELDOUT's views/ folder, the camera being the
file name up to its last '-'). Two figures, both relative RMSE of 4x4
block means: per channel over blocks wholly in the mask
(process::error_figures::block_relative_rmse), and of R+G+B over blocks
at least half in the mask (the `process` outdoor stage's block_rmse).

Exit 0 when the bounds hold, 1 when one does not, 2 for bad input.
"""

import argparse
import csv
import json
import math
import struct
import sys
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from rgbe import read_rgbe  # noqa: E402

ALBEDO_BOUND = 0.02
RENDER_BOUND = 0.03


def bad_input(msg):
    print(f"compare.py: {msg}", file=sys.stderr)
    sys.exit(2)


# ---------------------------------------------------------------- truth


def truth_at(entry, pts):
    """Reflectance (N, 3) of a truth surface at world points (N, 3)."""
    if "texture" not in entry:
        return np.tile(np.asarray(entry["rho"], float), (len(pts), 1))
    tex = entry["texture"]
    rel = np.asarray(pts, float) - np.asarray(tex["origin_m"], float)
    s = rel @ np.asarray(tex["s_axis"], float)
    t = rel @ np.asarray(tex["t_axis"], float)
    i = np.clip(np.floor(s / tex["pixel_m"]).astype(int), 0, tex["width"] - 1)
    j = np.clip(np.floor(t / tex["pixel_m"]).astype(int), 0, tex["height"] - 1)
    idx = np.asarray(tex["index"])[j, i]
    return np.asarray(tex["levels"], float)[idx]


def read_csv(path, need):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        bad_input(f"{path}: {e.strerror}")
    if not rows:
        bad_input(f"{path}: no rows")
    missing = [c for c in need if c not in rows[0]]
    if missing:
        bad_input(f"{path}: missing column(s) {', '.join(missing)}; header has {', '.join(rows[0])}")
    return rows


def num(path, row, col):
    try:
        return float(row[col])
    except ValueError:
        bad_input(f"{path}: cell {row.get('cell')}: {col} = {row[col]!r} is not a number")


def quantiles(v):
    v = np.asarray(v, float)
    v = v[np.isfinite(v)]
    if not len(v):
        return float("nan"), float("nan"), 0
    return float(np.median(v)), float(np.percentile(v, 95, method="nearest")), len(v)


def albedos(out, truth_path, status):
    out = Path(out)
    try:
        truth = json.loads(Path(truth_path).read_text())
    except (OSError, ValueError) as e:
        bad_input(f"{truth_path}: {e}")
    by_name = {s["name"]: s for s in truth["surfaces"]}
    cols = ["cell", "surface", "status"] + [f"rho_{k}_{c}" for k in ("sun", "se") for c in "rgb"]
    cells = read_csv(out / "cells.csv", cols)
    pts_rows = read_csv(out / "cell_points.csv", ["cell", "x", "y", "z"])
    pts = {}
    for r in pts_rows:
        pts.setdefault(r["cell"], []).append([num(out / "cell_points.csv", r, k) for k in "xyz"])
    statuses = {}
    per = {}
    for r in cells:
        statuses[r["status"]] = statuses.get(r["status"], 0) + 1
        if status and r["status"] not in status:
            continue
        s = r["surface"]
        if s not in by_name:
            bad_input(f"{out / 'cells.csv'}: cell {r['cell']}: surface {s!r} is not in {truth_path} "
                      f"(has {', '.join(by_name)})")
        if r["cell"] not in pts:
            bad_input(f"{out / 'cell_points.csv'}: no points for cell {r['cell']}")
        want = truth_at(by_name[s], pts[r["cell"]]).mean(0)
        for k in ("se", "sun"):
            got = np.array([num(out / "cells.csv", r, f"rho_{k}_{c}") for c in "rgb"])
            per.setdefault(s, {}).setdefault(k, []).append(np.abs(got / want - 1))
    print(f"cells by status: {statuses}" + (f"; scored: {', '.join(status)}" if status else "; scored: all"))
    print(f"{'surface':<12} {'rho':<6} {'cells':>5}  {'green median':>12} {'green p95':>9}   "
          f"{'r med':>6} {'g med':>6} {'b med':>6}   {'r p95':>6} {'g p95':>6} {'b p95':>6}")
    ok = True
    summary = {}
    for s in list(per) + ["overall"]:
        for k in ("se", "sun"):
            if s == "overall":
                e = np.concatenate([np.array(per[x][k]) for x in per]) if per else np.zeros((0, 3))
            else:
                e = np.array(per[s][k])
            qs = [quantiles(e[:, c]) for c in range(3)]
            g_med, g_p95, n = qs[1]
            print(f"{s:<12} {k:<6} {n:>5}  {100 * g_med:>11.2f}% {100 * g_p95:>8.2f}%   "
                  + " ".join(f"{100 * q[0]:>5.2f}%" for q in qs) + "   "
                  + " ".join(f"{100 * q[1]:>5.2f}%" for q in qs))
            summary[(s, k)] = g_med
    for k in ("se", "sun"):
        m = summary.get(("overall", k), float("nan"))
        verdict = "pass" if m <= ALBEDO_BOUND else "FAIL"
        ok &= m <= ALBEDO_BOUND
        print(f"rho_{k} green median over every scored cell: {100 * m:.2f}% (bound {100 * ALBEDO_BOUND:.0f}%): {verdict}")
    return ok


# ---------------------------------------------------------------- images


def read_pfm(path):
    data = Path(path).read_bytes()
    parts, pos = [], 0
    while len(parts) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        parts.append(data[pos:end].decode())
        pos = end
    pos += 1
    kind, w, h, scale = parts[0], int(parts[1]), int(parts[2]), float(parts[3])
    ch = 3 if kind == "PF" else 1
    img = np.frombuffer(data[pos : pos + 4 * w * h * ch], "<f4" if scale < 0 else ">f4").reshape(h, w, ch)
    img = img[::-1].astype(np.float32)
    return np.repeat(img, 3, 2) if ch == 1 else img


def read_exr(path):
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, np.float32)
        return np.stack([np.asarray(ch[c].pixels, np.float32) for c in "RGB"], -1)


def read_image(path):
    p = Path(path)
    try:
        if p.suffix.lower() == ".exr":
            return read_exr(p)
        if p.suffix.lower() == ".pfm":
            return read_pfm(p)
        return read_rgbe(p)
    except (OSError, ValueError, KeyError, IndexError) as e:
        bad_input(f"{p}: {e}")


def read_png_gray(path):
    """8-bit greyscale (or the first channel of 8-bit RGB/RGBA) PNG, any filter."""
    data = Path(path).read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        bad_input(f"{path}: not a PNG")
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, tag = struct.unpack(">I4s", data[pos : pos + 8])
        body = data[pos + 8 : pos + 8 + n]
        if tag == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            if depth != 8 or ctype not in (0, 2, 6):
                bad_input(f"{path}: bit depth {depth}, colour type {ctype}; expected 8-bit grey, RGB or RGBA")
            bpp = {0: 1, 2: 3, 6: 4}[ctype]
        elif tag == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = np.zeros((h, stride), np.int32)
    prev = np.zeros(stride, np.int32)
    for j in range(h):
        f = raw[j * (stride + 1)]
        line = np.frombuffer(raw[j * (stride + 1) + 1 : (j + 1) * (stride + 1)], np.uint8).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for i in range(stride):
            a = cur[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 0:
                x = 0
            elif f == 1:
                x = a
            elif f == 2:
                x = b
            elif f == 3:
                x = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                x = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[i] = (line[i] + x) & 255
        out[j] = cur
        prev = cur
    return out[:, ::bpp]


def block_rmse_per_channel(a, b, mask, k=4):
    h, w = mask.shape
    num = den = 0.0
    for by in range(h // k):
        for bx in range(w // k):
            sl = (slice(by * k, by * k + k), slice(bx * k, bx * k + k))
            if not mask[sl].all():
                continue
            ma, mb = a[sl].reshape(-1, 3).mean(0), b[sl].reshape(-1, 3).mean(0)
            num += float(((ma - mb) ** 2).sum())
            den += float((mb ** 2).sum())
    return math.sqrt(num / den) if den > 0 else float("nan")


def block_rmse_half(a, b, mask, k=4):
    h, w = mask.shape
    num = den = 0.0
    for by in range(h // k):
        for bx in range(w // k):
            sl = (slice(by * k, by * k + k), slice(bx * k, bx * k + k))
            m = mask[sl]
            if 2 * m.sum() >= k * k:
                sa, sb = a[sl][m].sum(), b[sl][m].sum()
                num += (sa - sb) ** 2
                den += sb * sb
    return math.sqrt(num / den) if den > 0 else float("nan")


def render(render_path, heldout_path, mask_path):
    a, b = read_image(render_path), read_image(heldout_path)
    if a.shape != b.shape:
        bad_input(f"{render_path}: {a.shape[1]}x{a.shape[0]}, but {heldout_path} is {b.shape[1]}x{b.shape[0]}")
    if mask_path is None:
        hp = Path(heldout_path)
        mask_path = hp.parent.parent / "masks" / (hp.stem.rsplit("-", 1)[0] + ".png")
    if not Path(mask_path).exists():
        bad_input(f"{mask_path}: no such mask (give --mask)")
    mask = read_png_gray(mask_path) > 0
    if mask.shape != a.shape[:2]:
        bad_input(f"{mask_path}: {mask.shape[1]}x{mask.shape[0]}, the images are {a.shape[1]}x{a.shape[0]}")
    if not np.all(np.isfinite(a[mask])):
        bad_input(f"{render_path}: non-finite values on target pixels")
    sa, sb = a[mask].sum(1), b[mask].sum(1)
    pix = math.sqrt(float(((sa - sb) ** 2).sum() / (sb ** 2).sum()))
    per_ch = block_rmse_per_channel(a, b, mask)
    half = block_rmse_half(a, b, mask)
    ratio = [float(a[mask][:, c].sum() / b[mask][:, c].sum()) for c in range(3)]
    print(f"{Path(render_path).name} vs {Path(heldout_path).name}: {int(mask.sum())} target pixels; "
          f"mean ratio r g b {ratio[0]:.4f} {ratio[1]:.4f} {ratio[2]:.4f}; pixel rel. RMSE {100 * pix:.2f}%; "
          f"4x4 blocks: per channel, whole blocks {100 * per_ch:.2f}%, R+G+B, half blocks {100 * half:.2f}% "
          f"(bound {100 * RENDER_BOUND:.0f}%): {'pass' if per_ch <= RENDER_BOUND else 'FAIL'}")
    return per_ch <= RENDER_BOUND


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs=2, help="OUT truth.json, or with --render: RENDER HELDOUT")
    ap.add_argument("--render", action="store_true")
    ap.add_argument("--mask")
    ap.add_argument("--status", action="append", help="score only cells with this status (repeatable)")
    a = ap.parse_args()
    ok = render(*a.paths, a.mask) if a.render else albedos(*a.paths, a.status)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
