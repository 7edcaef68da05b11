"""Campanile's normalized-cut segmenter on the simulated range scans, scored
by the same metrics as the Open3D rows (issue 28, "Peers").

    python campanile_segment.py SCANDIR SET --campanile BIN [--out DIR] [--params PARAMS.ron] [--header]

Runs `BIN segment SCANS... --out DIR` on the set's scans, in the order of
`SET.truth.json` (the order open3d_segment.py merges them in), then reads
every point's group from DIR/segmentation.ply: its vertices are the scans'
points in that order (positions as doubles, the group as an int, -1 for
unassigned; `scan/src/segmentation_ply.rs`). The positions are checked
against the scans' before scoring, so a reordered or filtered cloud stops
the script rather than scoring the wrong points.

The time column gives the segmenter's stages summed (segment-report.json's
`stages`: normals, clustering, graph, cuts, fine, ...; reading the scans,
meshing and writing the files not included), then the whole command's wall
time; the load average is read before and after the command. The metrics
and the row are open3d_segment.py's (`metrics`, `print_row`): one code
scores both tools.
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from open3d_segment import UNASSIGNED, loadavg, metrics, print_header, print_row, read_ply, read_set

# The derived parameters the row shows (the rest, and every reason, go to
# stderr); names the report does not hold are skipped.
MAIN_PARAMETERS = ["cluster_radius_m", "cluster_normal_deg", "cluster_intensity", "sigma_c_m", "anisotropy", "t_cut",
                   "coarse_sigma_w_normal_deg", "coarse_sigma_w_intensity"]


def parameter_text(name, value):
    """`cluster_radius 9.38 cm`, `cluster_normal 10°`, `t_cut 0.2`."""
    if name.endswith("_m"):
        return f"{name[:-2]} {100 * value:.3g} cm"
    if name.endswith("_deg"):
        return f"{name[:-4]} {value:.3g}°"
    return f"{name} {value:.3g}"


def scan_files(scandir, name):
    index = json.loads((scandir / f"{name}.truth.json").read_text())
    return [scandir / scan["scan_file"] for scan in index["scans"]]


def found_labels(out, xyz):
    """The groups of DIR/segmentation.ply's points (-1: unassigned), after
    checking that its vertices are `xyz`, point for point."""
    v = read_ply(out / "segmentation.ply")
    if len(v) != len(xyz):
        sys.exit(f"{out / 'segmentation.ply'}: {len(v)} points: expected the scans' {len(xyz)}")
    seg_xyz = np.stack([v["x"], v["y"], v["z"]], axis=1)
    moved = np.flatnonzero((seg_xyz != xyz).any(axis=1))
    if len(moved):
        i = moved[0]
        sys.exit(f"{out / 'segmentation.ply'}: vertex {i} is at {seg_xyz[i]}, the scans' point {i} at {xyz[i]}: "
                 f"expected the scans' points in their order ({len(moved)} differ)")
    group = v["group"].astype(np.int64)
    return np.where(group < 0, UNASSIGNED, group)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog="example: python campanile_segment.py /tmp/scans room "
                                        "--campanile target/release/campanile --header")
    ap.add_argument("scandir", type=Path)
    ap.add_argument("set", choices=["room", "building"])
    ap.add_argument("--campanile", type=Path, required=True, help="the campanile binary (a release build)")
    ap.add_argument("--out", type=Path, help="keep campanile's output here (default: a temporary directory)")
    ap.add_argument("--params", type=Path, help="passed to campanile segment --params")
    ap.add_argument("--header", action="store_true", help="print the table's header first")
    args = ap.parse_args()
    xyz, truth, surfaces = read_set(args.scandir, args.set)
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or Path(tmp)
        command = [str(args.campanile), "segment", *map(str, scan_files(args.scandir, args.set)), "--out", str(out)]
        if args.params:
            command += ["--params", str(args.params)]
        before = loadavg()
        clock = time.perf_counter()
        done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        seconds = time.perf_counter() - clock
        after = loadavg()
        # 0: ok or poor; 3: the verdict failed, the files written all the same.
        if done.returncode not in (0, 3):
            sys.exit(f"{' '.join(command)}: exit {done.returncode}\n{done.stderr}")
        report = json.loads((out / "segment-report.json").read_text())
        found = found_labels(out, xyz)
    if report["points"] != len(xyz):
        sys.exit(f"segment-report.json: points {report['points']}: expected the scans' {len(xyz)}")
    stages = sum(s["seconds"] for s in report["stages"])
    chosen = {c["name"]: c for c in report["parameters"]}
    shown = [n for n in MAIN_PARAMETERS if n in chosen] + [n for n, c in chosen.items()
                                                         if c["reason"] == "given" and n not in MAIN_PARAMETERS]
    params = ", ".join(parameter_text(n, chosen[n]["value"]) for n in shown)
    f = report["figures"]
    print(f"# {args.set} campanile: {report['groups']} groups, {report['unassigned']} unassigned, verdict "
          f"{report['verdict']} ({report['verdict_reason']}); spacing {100 * f['spacing_m']:.2f} cm, "
          f"noise {1000 * f['noise_m']:.2f} mm; stages "
          + ", ".join(f"{s['stage']} {s['seconds']:.1f} s" for s in report["stages"]), file=sys.stderr)
    for c in report["parameters"]:
        print(f"#     {c['name']} = {c['value']:.4g} ({c['reason']})", file=sys.stderr)
    if args.header:
        print_header()
    print_row(args.set, len(xyz), f"campanile segment ({report['groups']} groups)", params,
              f"{stages:.1f} (command {seconds:.1f})", before, after, metrics(xyz, truth, found, surfaces))


if __name__ == "__main__":
    main()
