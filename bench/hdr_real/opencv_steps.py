#!/usr/bin/env python3
"""One step of OpenCV's HDR pipeline, as a process of its own so that
/usr/bin/time measures it alone (bench/hdr_real/run.sh):

    opencv_steps.py calibrate SET_DIR CURVE.csv THREADS   # read frames, CalibrateDebevec
    opencv_steps.py merge SET_DIR CURVE.csv OUT.hdr THREADS  # read frames, MergeDebevec, write Radiance HDR

(opencv-python-headless 5.0 has no OpenEXR writer: the map is written as .hdr.)

SET_DIR holds the frames and times.txt ("FILE RELATIVE_EXPOSURE").
"""
import os
import pathlib
import sys

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")
import cv2  # noqa: E402
import numpy as np  # noqa: E402


def load(set_dir):
    files, times = [], []
    for line in (set_dir / "times.txt").read_text().splitlines():
        if line.strip():
            f, t = line.split()
            files.append(set_dir / f)
            times.append(float(t))
    images = [cv2.imread(str(f), cv2.IMREAD_COLOR) for f in files]
    for f, im in zip(files, images):
        if im is None:
            sys.exit(f"opencv_steps.py: cannot read {f}")
    return images, np.asarray(times, np.float32)


def main():
    step, set_dir = sys.argv[1], pathlib.Path(sys.argv[2])
    cv2.setNumThreads(int(sys.argv[-1]))
    images, times = load(set_dir)
    if step == "calibrate":
        crf = cv2.createCalibrateDebevec().process(images, times)
        np.savetxt(sys.argv[3], crf.reshape(256, 3), delimiter=",", header="b,g,r (linear)")
    elif step == "merge":
        crf = np.loadtxt(sys.argv[3], delimiter=",").astype(np.float32).reshape(256, 1, 3)
        hdr = cv2.createMergeDebevec().process(images, times, crf)
        if not cv2.imwrite(sys.argv[4], hdr):
            sys.exit(f"opencv_steps.py: cannot write {sys.argv[4]}")
    else:
        sys.exit(f"opencv_steps.py: unknown step {step!r}: expected calibrate or merge")


if __name__ == "__main__":
    main()
