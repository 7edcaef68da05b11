#!/usr/bin/env python3
"""Runs OpenCV's CalibrateDebevec and MergeDebevec on the stack written by
`hdr_bench`, measures memory bandwidth, and compares with Campanile's figures.

Usage: compare_opencv.py STACK_DIR CAMPANILE_FIGURES_FILE [REPEATS]
"""
import os
import sys
import time

import cv2
import numpy as np


def read_figures(path):
    out = {}
    for line in open(path):
        if line.startswith("sweep_"):
            continue
        if "=" in line:
            k, v = line.strip().split("=", 1)
            out[k] = float(v)
    return out


def memory_bandwidth_gbs(size_mb=512, repeats=5):
    """Copy bandwidth (read + write bytes / s) of a large array copy, best of N."""
    a = np.ones(size_mb * 1024 * 1024 // 8, dtype=np.float64)
    b = np.empty_like(a)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        np.copyto(b, a)
        best = min(best, time.perf_counter() - t0)
    return 2 * a.nbytes / best / 1e9


def log_rms(g, truth, lo=5, hi=250):
    d = g[lo:hi + 1] - truth[lo:hi + 1]
    d = d - d.mean()
    return float(np.sqrt((d * d).mean()))


def median(v):
    return float(np.median(np.asarray(v)))


def main():
    stack, figures_path = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    camp = read_figures(figures_path)
    times = np.array([float(t) for t in open(f"{stack}/times.txt").read().split()], dtype=np.float32)
    # cv2 reads BGR; convert to RGB so channel c matches the truth's column c.
    imgs = [cv2.cvtColor(cv2.imread(f"{stack}/exposure_{j}.png", cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
            for j in range(len(times))]
    h, w = imgs[0].shape[:2]
    truth = np.loadtxt(f"{stack}/truth_curve.csv", delimiter=",", skiprows=1)[:, 1:4]

    cal = cv2.createCalibrateDebevec(samples=1000)
    cal_ms = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        resp = cal.process(imgs, times)
        cal_ms.append((time.perf_counter() - t0) * 1e3)
    resp = resp.reshape(256, 3).astype(np.float64)
    with np.errstate(divide="ignore"):
        g_cv = np.log(resp)

    merge = cv2.createMergeDebevec()
    merge_ms = []
    for _ in range(max(repeats, 10)):
        t0 = time.perf_counter()
        hdr = merge.process(imgs, times, resp.reshape(256, 1, 3).astype(np.float32))
        merge_ms.append((time.perf_counter() - t0) * 1e3)

    truth_rad = np.fromfile(f"{stack}/truth_radiance.f32", dtype="<f4").reshape(h, w, 3)
    # Per-channel gauge: the median ratio to the truth, then the median relative error.
    errs = []
    for c in range(3):
        m, t = hdr[..., c].astype(np.float64), truth_rad[..., c].astype(np.float64)
        ok = (m > 0) & (t > 0) & np.isfinite(m)
        s = np.median(t[ok] / m[ok])
        errs.append(np.abs(m[ok] * s - t[ok]) / t[ok])
    cv_merge_err = float(np.median(np.concatenate(errs)))

    bw = memory_bandwidth_gbs()
    px_exp = w * h * len(times) / 1e6
    cv_merge = median(merge_ms)
    cv_cal = median(cal_ms)
    cv_tp = px_exp / (cv_merge / 1e3)
    camp_tp = camp["campanile_merge_mpx_exp_per_s"]
    # Bytes the Campanile merge must move per pixel·exposure: 3 u16 codes read
    # (6 B) + its share of 6 f32 written (radiance and variance, 24 B) and
    # the mask byte.
    bytes_per_px_exp = 6 + (24 + 1) / len(times)
    print(f"stack: {w}x{h}, {len(times)} exposures, 8-bit PNG; OpenCV {cv2.__version__}, "
          f"{cv2.getNumThreads()} OpenCV threads, {int(camp['threads'])} Campanile threads")
    print(f"memory_bandwidth_copy_gb_s={bw:.2f}")
    print(f"opencv_calibrate_ms={cv_cal:.2f}")
    print(f"campanile_calibrate_ms={camp['campanile_calibrate_ms']:.2f}")
    print(f"calibrate_time_ratio_opencv_over_campanile={cv_cal / camp['campanile_calibrate_ms']:.2f}")
    print(f"opencv_merge_ms={cv_merge:.2f}")
    print(f"campanile_merge_ms={camp['campanile_merge_ms']:.2f}")
    print(f"opencv_merge_mpx_exp_per_s={cv_tp:.1f}")
    print(f"campanile_merge_mpx_exp_per_s={camp_tp:.1f}")
    print(f"merge_throughput_ratio={camp_tp / cv_tp:.1f}  (medians; goal >= 30)")
    cv_best_tp = px_exp / (min(merge_ms) / 1e3)
    camp_best_tp = camp["campanile_merge_best_mpx_exp_per_s"]
    print(f"merge_best_of_runs: opencv={cv_best_tp:.1f} campanile={camp_best_tp:.1f} Mpx*exp/s, "
          f"ratio={camp_best_tp / cv_best_tp:.1f}")
    print(f"machine load average during the run: {os.getloadavg()[0]:.2f} (2 cores)")
    print(f"campanile_merge_bandwidth_gb_s={camp_tp * 1e6 * bytes_per_px_exp / 1e9:.2f} "
          f"({100 * camp_tp * 1e6 * bytes_per_px_exp / 1e9 / bw:.0f}% of numpy's one-thread copy bandwidth)")
    # The roofline hdr_bench measured in its own process, on the merge's threads.
    for key in ("memory_copy_gb_s", "merge_best_gb_s", "merge_share_of_copy_roofline",
                "same_traffic_kernel_best_ms", "merge_share_of_same_traffic_kernel"):
        if key in camp:
            print(f"hdr_bench_{key}={camp[key]:.3f}")
    for c, name in enumerate("rgb"):
        print(f"curve_log_rms_{name}: campanile={camp[f'campanile_curve_log_rms_{name}']:.5f} "
              f"opencv={log_rms(g_cv[:, c], truth[:, c]):.5f}")
    print(f"campanile_robertson: {camp['campanile_robertson_calibrate_ms']:.1f} ms, "
          f"curve log-RMS (mean of R, G, B) {camp['campanile_robertson_curve_log_rms_mean']:.5f}")
    print(f"merge_median_rel_error: campanile={camp['campanile_merge_median_rel_error']:.5f} "
          f"opencv={cv_merge_err:.5f} (OpenCV with its own curve; Campanile: valid pixels)")


def print_sweep(path):
    print("Campanile Debevec-Malik knob sweep (samples per channel, dark-end correction):")
    for line in open(path):
        if line.startswith("sweep_"):
            print("  " + line.strip())


if __name__ == "__main__":
    main()
    print_sweep(sys.argv[2])
