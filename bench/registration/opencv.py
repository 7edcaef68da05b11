#!/usr/bin/env python3
"""Times OpenCV on the inputs `cargo bench -p campanile-process --bench
registration -- DIR` wrote: AprilTag 36h11 detection (cv2.aruco) on each
wall photo, and solvePnP (SQPnP then ITERATIVE, its Levenberg-Marquardt)
and solvePnPRansac on the same correspondences Campanile registered.
Prints a Markdown table beside Campanile's figures (from the JSON)."""
import json
import sys
import time
from pathlib import Path

import cv2
import numpy as np


def median_ms(f, runs=15):
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return 1e3 * sorted(ts)[len(ts) // 2]


def main():
    d = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/campanile-registration-bench")
    print(f"OpenCV {cv2.__version__}")
    print("| targets | OpenCV tags found | OpenCV detection | solvePnP (SQPnP + LM) | solvePnPRansac | Campanile detection | Campanile registration |")
    print("|---|---|---|---|---|---|---|")
    for n in (50, 100):
        meta = json.loads((d / f"wall-{n}.json").read_text())
        img = cv2.imread(str(d / f"wall-{n}.png"), cv2.IMREAD_GRAYSCALE)
        det = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11),
                                      cv2.aruco.DetectorParameters())
        corners, ids, _ = det.detectMarkers(img)
        found = 0 if ids is None else len(ids)
        t_det = median_ms(lambda: det.detectMarkers(img), runs=5)
        f = meta["focal_px"]
        cx, cy = meta["principal_px"]
        K = np.array([[f, 0, cx], [0, f, cy], [0, 0, 1]], float)
        dist = np.array([meta["k1"], meta["k2"], 0, 0, 0], float)
        world = np.array([p["world"] for p in meta["points"]], float)
        pix = np.array([p["pixel"] for p in meta["points"]], float)

        def pnp():
            ok, r, t = cv2.solvePnP(world, pix, K, dist, flags=cv2.SOLVEPNP_SQPNP)
            cv2.solvePnP(world, pix, K, dist, rvec=r, tvec=t, useExtrinsicGuess=True, flags=cv2.SOLVEPNP_ITERATIVE)

        def ransac():
            cv2.solvePnPRansac(world, pix, K, dist, reprojectionError=4.0, confidence=0.9999, iterationsCount=500)

        t_pnp = median_ms(pnp)
        t_ransac = median_ms(ransac)
        print(f"| {n} | {found} | {t_det:.1f} ms | {t_pnp:.2f} ms | {t_ransac:.2f} ms | "
              f"{meta['campanile_detection_ms']:.1f} ms | {meta['campanile_registration_ms']:.2f} ms |")


if __name__ == "__main__":
    main()
