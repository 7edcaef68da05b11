#!/usr/bin/env python3
"""Leave-one-out consistency of the merge on the real sets.

For each set: the central CROP×CROP pixels of every frame are written as
8-bit PNG (decoded once by Pillow, cropped, no resampling), then merged with
all frames and with each frame left out, by

- Campanile (`campanile hdr merge --curve <set>/campanile_debevec.csv`, the
  curve calibrated on the full set by campanile_curves.sh), and
- OpenCV `MergeDebevec` with OpenCV's own Debevec curve of the full set
  (`<set>/opencv_debevec.csv` from peers.py).

Figure: the median, over the well-exposed pixels and the three channels, of
|M_without_k / M_all − 1|. Well-exposed: pixels whose codes lie in LO..HI
(default 10..245) in every channel in at least two frames, so that every
leave-one-out merge still has a well-exposed sample there.

    venv=$(bench/venv.sh opencv-python-headless numpy pillow OpenEXR)
    "$venv/bin/python" validation/hdr/loo.py [--crop 1024] [SET...]

Writes `<set>/loo.csv` (tool, frame left out, median, p95) and prints a
markdown summary.
"""

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")
import cv2  # noqa: E402
import OpenEXR  # noqa: E402
from PIL import Image  # noqa: E402


def sets_root():
    return pathlib.Path(
        os.environ.get(
            "CAMPANILE_HDR_SETS",
            os.path.join(os.environ.get("TMPDIR", "/tmp"), "campanile-validation", "hdr"),
        )
    )


def read_times(set_dir):
    files, times = [], []
    for line in (set_dir / "times.txt").read_text().splitlines():
        if line.strip():
            f, t = line.split()
            files.append(set_dir / f)
            times.append(float(t))
    return files, times


def read_ln_curve(path):
    rows = [ln for ln in path.read_text().splitlines() if ln and not ln.startswith("#")]
    head = rows[0].split(",")
    idx = [head.index(f"ln_exposure_{c}") for c in "rgb"]
    ln = np.array([[float(r.split(",")[i]) for i in idx] for r in rows[1:]])
    if ln.shape[0] != 256:
        raise SystemExit(f"loo.py: {path}: {ln.shape[0]} codes, expected 256")
    return ln


def crop_pngs(files, out_dir, crop):
    out = []
    for f in files:
        im = Image.open(f).convert("RGB")
        w, h = im.size
        c = min(crop, w, h)
        x0, y0 = (w - c) // 2, (h - c) // 2
        p = out_dir / (f.stem + ".png")
        im.crop((x0, y0, x0 + c, y0 + c)).save(p)
        out.append(p)
    return out


def read_exr_rgb(path):
    with OpenEXR.File(str(path)) as f:
        ch = f.parts[0].channels
        if "RGB" in ch:  # the OpenEXR module groups R, G, B into one channel
            return np.asarray(ch["RGB"].pixels, dtype=np.float64)[:, :, :3]
        return np.stack([np.asarray(ch[k].pixels, dtype=np.float64) for k in ("R", "G", "B")], axis=-1)


def campanile_merge(binary, pngs, times, curve, out):
    cmd = [binary, "hdr", "merge", *map(str, pngs), "--times", ",".join(repr(t) for t in times), "--curve", str(curve), "-o", str(out)]
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    if r.returncode != 0:
        raise SystemExit(f"loo.py: campanile hdr merge failed ({r.returncode}): {r.stderr.decode()[-500:]}")
    return read_exr_rgb(out)


def opencv_merge(images_bgr, times, ln_rgb):
    lin = np.exp(ln_rgb)
    # Fill codes the curve leaves undefined with the nearest defined one.
    for c in range(3):
        ok = np.isfinite(lin[:, c])
        lin[:, c] = np.interp(np.arange(256), np.flatnonzero(ok), lin[ok, c])
    resp = lin[:, ::-1].astype(np.float32).reshape(256, 1, 3)
    m = cv2.createMergeDebevec().process(images_bgr, np.asarray(times, np.float32), resp)
    return m[:, :, ::-1].astype(np.float64)


def rel_change(m, ref, mask):
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.abs(m / ref - 1.0)
    v = r[mask]
    v = v[np.isfinite(v)]
    return float(np.median(v)), float(np.percentile(v, 95))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sets", nargs="*")
    ap.add_argument("--crop", type=int, default=1024)
    ap.add_argument("--lo", type=int, default=10)
    ap.add_argument("--hi", type=int, default=245)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--bin", default=str(pathlib.Path(__file__).resolve().parents[2] / "target" / "release" / "campanile"))
    a = ap.parse_args()
    cv2.setNumThreads(a.threads)
    root = sets_root()
    names = a.sets or sorted(p.name for p in root.iterdir() if (p / "campanile_debevec.csv").exists())
    print("| set | frames | crop | well-exposed px | tool | median of medians | worst frame left out (median) |")
    print("|---|---|---|---|---|---|---|")
    for name in names:
        d = root / name
        files, times = read_times(d)
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            pngs = crop_pngs(files, tmp, a.crop)
            imgs = [cv2.imread(str(p), cv2.IMREAD_COLOR) for p in pngs]
            codes = np.stack([im[:, :, ::-1] for im in imgs])  # N, H, W, 3 (RGB)
            good = ((codes >= a.lo) & (codes <= a.hi)).all(axis=-1).sum(axis=0) >= 2
            mask = np.repeat(good[:, :, None], 3, axis=2)
            rows = []
            summary = []
            tools = [
                ("campanile", lambda p, t, i: campanile_merge(a.bin, p, t, d / "campanile_debevec.csv", tmp / "m.exr")),
                ("opencv", lambda p, t, i: opencv_merge(i, t, read_ln_curve(d / "opencv_debevec.csv"))),
            ]
            for tool, merge in tools:
                ref = merge(pngs, times, imgs)
                meds = []
                for k in range(len(pngs)):
                    keep = [i for i in range(len(pngs)) if i != k]
                    m = merge([pngs[i] for i in keep], [times[i] for i in keep], [imgs[i] for i in keep])
                    med, p95 = rel_change(m, ref, mask)
                    meds.append(med)
                    rows.append((tool, files[k].name, med, p95))
                worst = int(np.argmax(meds))
                summary.append((tool, float(np.median(meds)), files[worst].name, meds[worst]))
            c = codes.shape[1]
        with open(d / "loo.csv", "w") as f:
            f.write("tool,left_out,median_rel_change,p95_rel_change\n")
            for r in rows:
                f.write(f"{r[0]},{r[1]},{r[2]:.6f},{r[3]:.6f}\n")
        for tool, mm, wf, wm in summary:
            print(
                f"| {name} | {len(files)} | {c}² | {int(good.sum())} | {tool} | {100 * mm:.3f}% | {wf} ({100 * wm:.3f}%) |",
                flush=True,
            )


if __name__ == "__main__":
    sys.exit(main())
