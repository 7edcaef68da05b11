#!/usr/bin/env python3
"""Response curves of the real bracket sets by tools that share no code with
Campanile, written as CSV (`code,ln_exposure_r,ln_exposure_g,ln_exposure_b`;
ln of relative exposure per 8-bit code, NaN where the tool gives none):

- OpenCV `createCalibrateDebevec` and `createCalibrateRobertson` on the full
  set with the EXIF exposures (`<set>/opencv_debevec.csv`,
  `<set>/opencv_robertson.csv`);
- pfstools `pfsinhdrgen | pfshdrcalibrate` (Robertson 2002, pfstools'
  implementation) when the Debian package is installed
  (`<set>/pfstools_robertson.csv`);
- the hdrgen response curve a set ships (`Response_function.rsp`, three
  polynomials in the normalized code, highest power first), evaluated as
  hdrgen does (hdrgen_rsp.py: x = (code + 0.5)/256, linear toe below code
  19) and converted to ln exposure per code
  (`<set>/hdrgen_rsp.csv`).

Run with the bench venv (outside the repository):

    venv=$(bench/venv.sh opencv-python-headless numpy)
    "$venv/bin/python" validation/hdr/peers.py [SET...]

Sets are read from ${CAMPANILE_HDR_SETS:-${TMPDIR:-/tmp}/campanile-validation/hdr}
(made by fetch_sets.sh); each needs `times.txt` ("FILE RELATIVE_EXPOSURE").
Curves are written beside the images; `--threads N` sets cv2.setNumThreads.
"""

import argparse
import math
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

import cv2
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import hdrgen_rsp  # noqa: E402


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


def write_curve(path, ln_rgb, header):
    """ln_rgb: array (256, 3) in R, G, B order."""
    with open(path, "w") as f:
        f.write(f"# {header}\n")
        f.write("code,ln_exposure_r,ln_exposure_g,ln_exposure_b\n")
        for z in range(ln_rgb.shape[0]):
            f.write(f"{z}," + ",".join("nan" if not np.isfinite(v) else f"{v:.9f}" for v in ln_rgb[z]) + "\n")


def stride_for(shape, max_mp):
    """Pixel stride that keeps at most max_mp megapixels per frame."""
    return max(1, math.ceil(math.sqrt(shape[0] * shape[1] / (max_mp * 1e6))))


def opencv_curves(images, times, out_dir, samples, stride):
    t = np.asarray(times, dtype=np.float32)
    res = {}
    t0 = time.perf_counter()
    deb = cv2.createCalibrateDebevec(samples=samples).process(images, t)
    res["debevec_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    # Robertson uses every pixel: on large frames, every stride-th pixel of
    # every stride-th row (camera pixels picked, none averaged).
    picked = [np.ascontiguousarray(im[::stride, ::stride]) for im in images]
    rob = cv2.createCalibrateRobertson().process(picked, t)
    res["robertson_s"] = time.perf_counter() - t0
    for name, crf in (("opencv_debevec", deb), ("opencv_robertson", rob)):
        lin = crf.reshape(256, 3)[:, ::-1].astype(np.float64)  # BGR -> RGB
        with np.errstate(divide="ignore", invalid="ignore"):
            ln = np.where(lin > 0, np.log(lin), np.nan)
        write_curve(
            out_dir / f"{name}.csv",
            ln,
            f"OpenCV {cv2.__version__} {name.split('_')[1]} "
            f"({'samples=%d, full frames' % samples if name.endswith('debevec') else 'every %d-th pixel' % stride}, defaults otherwise), "
            f"{len(images)} frames",
        )
    return res


def parse_octave_matrices(text):
    """The matrices of an Octave text file, by name (pfstools' --save-response)."""
    out, name, rows = {}, None, []
    for line in text.splitlines():
        m = re.match(r"# name: (\S+)", line)
        if m:
            if name is not None:
                out[name] = np.array(rows, dtype=float)
            name, rows = m.group(1), []
        elif line.startswith("#") or not line.strip():
            continue
        elif name is not None:
            rows.append([float(v) for v in line.split()])
    if name is not None:
        out[name] = np.array(rows, dtype=float)
    return out


def pfstools_curve(files, images, times, out_dir, stride):
    if shutil.which("pfsinhdrgen") is None or shutil.which("pfshdrcalibrate") is None:
        print("peers.py: pfstools not installed (apt-get install pfstools); skipped", file=sys.stderr)
        return None
    with tempfile.TemporaryDirectory() as tmp:
        if stride > 1:
            # pfshdrcalibrate uses every pixel: give it every stride-th pixel
            # (lossless PNG, camera pixels picked, none averaged).
            picked = []
            for i, im in enumerate(images):
                p = pathlib.Path(tmp) / f"frame{i:03d}.png"
                cv2.imwrite(str(p), np.ascontiguousarray(im[::stride, ::stride]))
                picked.append(p)
            files = picked
        script = pathlib.Path(tmp) / "set.hdrgen"
        # hdrgen script: FILE 1/t APERTURE ISO 0; the relative exposure is
        # carried by 1/t alone (aperture 1, ISO 100 for every frame).
        script.write_text("".join(f"{f} {1.0 / t!r} 1 100 0\n" for f, t in zip(files, times)))
        resp = pathlib.Path(tmp) / "response.m"
        t0 = time.perf_counter()
        p1 = subprocess.Popen(["pfsinhdrgen", str(script)], stdout=subprocess.PIPE)
        p2 = subprocess.run(
            ["pfshdrcalibrate", "-c", "robertson", "-s", str(resp)],
            stdin=p1.stdout,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        p1.stdout.close()
        p1.wait()
        elapsed = time.perf_counter() - t0
        if p2.returncode != 0 or not resp.exists():
            print(f"peers.py: pfshdrcalibrate failed: {p2.stderr.decode()[-400:]}", file=sys.stderr)
            return None
        mats = parse_octave_matrices(resp.read_text())
    ln = np.full((256, 3), np.nan)
    for c, key in enumerate(("IR", "IG", "IB")):
        m = mats.get(key)
        if m is None:
            raise SystemExit(f"peers.py: pfstools response has no {key} (has {sorted(mats)})")
        # one column per code: pfstools writes the linear relative exposure
        v = m[:, -1] if m.ndim == 2 else m
        if v.size != 256:
            raise SystemExit(f"peers.py: pfstools {key} has {v.size} entries, expected 256")
        with np.errstate(divide="ignore", invalid="ignore"):
            ln[:, c] = np.where(v > 0, np.log(v), np.nan)
    write_curve(
        out_dir / "pfstools_robertson.csv",
        ln,
        f"pfstools pfshdrcalibrate -c robertson, {len(files)} frames, every {stride}-th pixel",
    )
    return {"pfstools_s": elapsed}


def rsp_curve(rsp_path, out_dir):
    """hdrgen .rsp as hdrgen evaluates it (hdrgen_rsp.py: x = (code + 0.5)/256,
    linear toe below code 19), as ln exposure per code."""
    try:
        ln = np.array(hdrgen_rsp.ln_curve(rsp_path))
    except ValueError as e:
        raise SystemExit(f"peers.py: {e}")
    write_curve(
        out_dir / "hdrgen_rsp.csv",
        ln,
        f"hdrgen response {rsp_path.name} (as hdrgen evaluates it: x = (code + 0.5)/256, linear toe below code 19)",
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sets", nargs="*")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--samples", type=int, default=70, help="CalibrateDebevec samples (OpenCV default 70)")
    ap.add_argument("--no-pfstools", action="store_true")
    ap.add_argument("--max-mp", type=float, default=1.0, help="megapixels per frame for the all-pixel methods (Robertson)")
    a = ap.parse_args()
    cv2.setNumThreads(a.threads)
    root = sets_root()
    names = a.sets or sorted(p.name for p in root.iterdir() if (p / "times.txt").exists())
    for name in names:
        d = root / name
        files, times = read_times(d)
        images = [cv2.imread(str(f), cv2.IMREAD_COLOR) for f in files]
        for f, im in zip(files, images):
            if im is None:
                raise SystemExit(f"peers.py: OpenCV cannot read {f}")
        stride = stride_for(images[0].shape, a.max_mp)
        figs = opencv_curves(images, times, d, a.samples, stride)
        figs["stride"] = stride
        if not a.no_pfstools:
            r = pfstools_curve(files, images, times, d, stride)
            if r:
                figs.update(r)
        if (d / "Response_function.rsp").exists():
            rsp_curve(d / "Response_function.rsp", d)
        print(name, " ".join(f"{k}={v:.2f}" for k, v in figs.items()), flush=True)


if __name__ == "__main__":
    main()
