"""Open3D's plane segmentation on the simulated range scans, scored against
their true surfaces (issue 28, "Peers").

    python open3d_segment.py SCANDIR SET [--methods ransac,patches] [--check-metrics] [--header]

SCANDIR holds the scans and truth written by
`cargo run -p campanile-sim --example range_scans -- SCANDIR --truth`
(format: `sim/src/world/range_truth.rs`); SET is `room` or `building`.
The PLY scans of the set are merged (their points are already in the scene
frame) and segmented by Open3D the way its users do it:

- `ransac`: iterated `segment_plane` (RANSAC, 3 points a hypothesis): take
  the best plane's inliers out and repeat until fewer than MIN_PLANE points
  fit a plane or fewer than REST of the points remain; each plane's inliers
  are split by `cluster_dbscan` into connected pieces (coplanar but separate
  surfaces; run on one point per voxel of the spacing's size, each point
  taking its voxel's piece), DBSCAN's noise left unassigned. The points left at the end are
  unassigned.
- `patches`: `estimate_normals` (hybrid KNN/radius search), then
  `detect_planar_patches` (Open3D >= 0.17, Araujo & Oliveira 2020's robust
  statistics plane detection), which returns oriented boxes; a point is in
  the patch whose box holds it and whose plane (the box's thinnest axis
  through its centre) is nearest; points in no box are unassigned.

The parameters are set per scene from the scanner's noise (σ 3 mm) and the
point spacing (printed); see PARAMETERS.

# The metrics (bench/segment/README.md says the same)

Points P of the merged cloud; t(p) the true surface or "unassigned" (a
mixed pixel, on no surface); s(p) the found segment or "unassigned".
The points scored are the truth-assigned ones, P_t = {p : t(p) assigned}.
Counted surfaces: true surfaces with at least MIN_SURFACE (100) points.

- map: each found segment S maps to the true surface m(S) holding most of
  S's points in P_t (ties: the lower surface index); a segment with no point
  in P_t maps to nothing.
- right: |{p in P_t : s(p) assigned and m(s(p)) = t(p)}| / |P_t|. Points the
  method leaves unassigned count as wrong.
- missed: counted surfaces T whose points went mostly nowhere: among the
  buckets "each segment" and "unassigned", the one holding most of T's points
  is "unassigned".
- under: counted, not missed surfaces T whose plurality segment (the segment
  holding most of T's points) maps to another surface than T.
- over: counted surfaces T split over 2 or more segments that each hold at
  least 5 % of T's points.
- boundary error (cm): a point p in P_t is next to a true boundary when one
  of its K = 8 nearest neighbours in P_t (Euclidean, the merged cloud, p
  itself excluded) has another true surface. A point p with s(p) assigned is
  on a found boundary when one of its K nearest neighbours among the
  assigned points has another segment. For each point next to a true
  boundary, the distance to the nearest point on a found boundary; reported
  as the share within 2 cm (the issue's goal), the mean and the 95th
  percentile, in cm ("none" when nothing is on a found boundary).

The neighbour searches of the metrics use scipy's cKDTree, not Open3D.
"""

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree

UNASSIGNED = -1
MIN_SURFACE = 100
K = 8
SPLIT_SHARE = 0.05
BOUNDARY_GOAL = 0.02
EPS_VOXELS = 4

# Per scene: RANSAC's distance threshold (about 3σ of the 3 mm range noise,
# more at the tower's ranges where the grid is coarse), the smallest plane
# worth taking, DBSCAN's radius (a few times the point spacing at the far
# surfaces) and the normals' search (radius, neighbours). DBSCAN runs on one
# point per voxel whose side is the 99th percentile of the nearest-neighbour
# spacing, with a radius of EPS_VOXELS voxels, so that its neighbourhoods hold
# a like number of points (and memory) at every resolution and range.
PARAMETERS = {
    "room": dict(distance=0.01, iterations=1000, min_plane=500, rest=0.01, dbscan_min=10,
                 normal_radius=0.05, normal_nn=30),
    "building": dict(distance=0.03, iterations=1000, min_plane=500, rest=0.01, dbscan_min=10,
                     normal_radius=0.6, normal_nn=30),
}


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def read_ply(path):
    """The vertices of a binary little-endian PLY as a structured array."""
    types = {"double": "<f8", "float": "<f4", "int": "<i4", "uchar": "u1", "ushort": "<u2", "uint": "<u4"}
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            sys.exit(f"{path}: not a PLY file")
        fields, count, element = [], None, None
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: the header has no end_header")
            words = line.decode("ascii").split()
            if words[0] == "format" and words[1] != "binary_little_endian":
                sys.exit(f"{path}: format {words[1]}: expected binary_little_endian")
            if words[0] == "element":
                element = words[1]
                if element == "vertex":
                    count = int(words[2])
            if words[0] == "property" and element == "vertex":
                fields.append((words[2], types[words[1]]))
            if words[0] == "end_header":
                break
        data = np.fromfile(f, dtype=np.dtype(fields), count=count)
    if len(data) != count:
        sys.exit(f"{path}: {len(data)} vertices: expected {count}")
    return data


def read_set(scandir, name):
    """The merged points and true labels (-1: unassigned) of a set."""
    index = json.loads((scandir / f"{name}.truth.json").read_text())
    points, labels = [], []
    for scan in index["scans"]:
        if not scan["scan_file"].endswith(".ply"):
            sys.exit(f"{scan['scan_file']}: this script reads the PLY scans (range_scans --format ply)")
        v = read_ply(scandir / scan["scan_file"])
        t = np.fromfile(scandir / scan["truth"], dtype="<u4")
        if len(t) != len(v) or len(v) != scan["points"]:
            sys.exit(f"{scan['truth']}: {len(t)} labels for {len(v)} points: expected {scan['points']} each")
        points.append(np.stack([v["x"], v["y"], v["z"]], axis=1))
        labels.append(np.where(t == index["unassigned"], UNASSIGNED, t.astype(np.int64)))
    return np.concatenate(points), np.concatenate(labels), index["surfaces"]


def ransac_planes(pcd, p):
    """Iterated segment_plane, each plane's inliers split by DBSCAN."""
    n = len(pcd.points)
    found = np.full(n, UNASSIGNED, dtype=np.int64)
    remaining = np.arange(n)
    rest = pcd
    segments, planes = 0, 0
    while len(remaining) > max(p["rest"] * n, p["min_plane"]):
        _, inliers = rest.segment_plane(distance_threshold=p["distance"], ransac_n=3,
                                        num_iterations=p["iterations"])
        inliers = np.asarray(inliers, dtype=np.int64)
        if len(inliers) < p["min_plane"]:
            break
        planes += 1
        pieces = coplanar_pieces(np.asarray(rest.points)[inliers], p)
        kept = pieces >= 0
        found[remaining[inliers[kept]]] = segments + pieces[kept]
        segments += int(pieces.max()) + 1 if kept.any() else 0
        rest = rest.select_by_index(inliers, invert=True)
        mask = np.ones(len(remaining), dtype=bool)
        mask[inliers] = False
        remaining = remaining[mask]
    return found, f"{planes} planes"


def coplanar_pieces(xyz, p):
    """DBSCAN's pieces of one plane's inliers (-1: noise), clustered on one
    point per voxel of the spacing's size (dense parts near the scanner
    would otherwise give DBSCAN thousands of neighbours a point), each
    point taking its voxel's piece."""
    keys = np.floor(xyz / p["voxel"]).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    voxels = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz[first]))
    return np.asarray(voxels.cluster_dbscan(eps=p["eps"], min_points=p["dbscan_min"]))[inverse.ravel()]


def planar_patches(pcd, p):
    """estimate_normals, detect_planar_patches, points to their box."""
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=p["normal_radius"], max_nn=p["normal_nn"]))
    boxes = pcd.detect_planar_patches(normal_variance_threshold_deg=60, coplanarity_deg=75, outlier_ratio=0.75,
                                      min_plane_edge_length=0, min_num_points=0,
                                      search_param=o3d.geometry.KDTreeSearchParamKNN(knn=30))
    xyz = np.asarray(pcd.points)
    found = np.full(len(xyz), UNASSIGNED, dtype=np.int64)
    best = np.full(len(xyz), np.inf)
    for i, box in enumerate(boxes):
        inside = np.asarray(box.get_point_indices_within_bounding_box(pcd.points), dtype=np.int64)
        if len(inside) == 0:
            continue
        axes = np.asarray(box.R)
        normal = axes[:, int(np.argmin(np.asarray(box.extent)))]
        d = np.abs((xyz[inside] - np.asarray(box.center)) @ normal)
        closer = d < best[inside]
        best[inside[closer]] = d[closer]
        found[inside[closer]] = i
    return found, f"{len(boxes)} patches"


def plurality(a, b, na, nb):
    """For each value of a (0..na), the value of b (0..nb) most often with it
    (ties: the lowest), and the counts table."""
    table = np.zeros((na, nb), dtype=np.int64)
    np.add.at(table, (a, b), 1)
    return table.argmax(axis=1), table


def boundary_points(tree, labels, points):
    """Points one of whose K nearest neighbours (in the tree of `points`)
    has another label."""
    _, nn = tree.query(points, k=K + 1, workers=-1)
    return (labels[nn[:, 1:]] != labels[:, None]).any(axis=1)


def metrics(xyz, truth, found, surfaces):
    scored = truth != UNASSIGNED
    t, s = truth[scored], found[scored]
    n_surf = len(surfaces)
    segments = int(found.max()) + 1 if (found >= 0).any() else 0
    # m(S): each segment's true surface (segments with no scored point: -1).
    assigned = s >= 0
    m, seg_table = plurality(s[assigned], t[assigned], max(segments, 1), n_surf)
    m = np.where(seg_table.sum(axis=1) > 0, m, -1)
    right = np.count_nonzero(assigned & (m[np.where(assigned, s, 0)] == t)) / len(t)
    # Each surface's points over the buckets: segments, then unassigned.
    bucket = np.where(assigned, s, segments)
    _, surf_table = plurality(t, bucket, n_surf, segments + 1)
    sizes = surf_table.sum(axis=1)
    counted = sizes >= MIN_SURFACE
    top = surf_table.argmax(axis=1)
    missed = counted & (top == segments)
    top_seg = surf_table[:, :segments].argmax(axis=1) if segments else np.zeros(n_surf, dtype=np.int64)
    under = counted & ~missed & (m[top_seg] != np.arange(n_surf)) if segments else np.zeros(n_surf, bool)
    big_pieces = (surf_table[:, :segments] >= SPLIT_SHARE * np.maximum(sizes, 1)[:, None]).sum(axis=1)
    over = counted & (big_pieces >= 2)
    # Boundaries.
    xyz_t = xyz[scored]
    true_b = boundary_points(cKDTree(xyz_t), t, xyz_t)
    xyz_f = xyz[found >= 0]
    if len(xyz_f) > K:
        found_b = boundary_points(cKDTree(xyz_f), found[found >= 0], xyz_f)
    else:
        found_b = np.zeros(len(xyz_f), dtype=bool)
    if found_b.any() and true_b.any():
        d, _ = cKDTree(xyz_f[found_b]).query(xyz_t[true_b], k=1, workers=-1)
        boundary = (float(np.mean(d <= BOUNDARY_GOAL)), 100 * float(np.mean(d)), 100 * float(np.percentile(d, 95)))
    else:
        boundary = None
    name = lambda mask: ",".join(surfaces[i] for i in np.flatnonzero(mask)) or "-"
    return dict(right=right, under=int(under.sum()), over=int(over.sum()), missed=int(missed.sum()),
                counted=int(counted.sum()), segments=segments, boundary=boundary, true_boundary=int(true_b.sum()),
                under_names=name(under), over_names=name(over), missed_names=name(missed))


def check_metrics(xyz, truth, surfaces):
    """The metrics' known answers on this cloud: the truth itself as the
    segmentation (all right, nothing under, over or missed, every boundary
    at 0 cm), one segment for everything (right = the largest surface's
    share, every other counted surface under-segmented), and nothing
    assigned (0 right, every counted surface missed). Exits 1 on a miss."""
    sizes = np.bincount(truth[truth >= 0], minlength=len(surfaces))
    counted = int((sizes >= MIN_SURFACE).sum())
    cases = [
        ("truth", truth, dict(right=1.0, under=0, over=0, missed=0), (1.0, 0.0, 0.0)),
        ("one segment", np.zeros_like(truth), dict(right=sizes.max() / sizes.sum(), under=counted - 1, over=0,
                                                   missed=0), None),
        ("nothing", np.full_like(truth, UNASSIGNED), dict(right=0.0, under=0, over=0, missed=counted), None),
    ]
    bad = 0
    for name, found, expected, boundary in cases:
        m = metrics(xyz, truth, found, surfaces)
        for key, value in expected.items():
            if abs(m[key] - value) > 1e-12:
                print(f"check {name}: {key} = {m[key]}, expected {value}", file=sys.stderr)
                bad += 1
        if boundary != m["boundary"]:
            print(f"check {name}: boundary = {m['boundary']}, expected {boundary}", file=sys.stderr)
            bad += 1
    print(f"# metrics check on {len(truth)} points: {'ok' if bad == 0 else f'{bad} misses'}", file=sys.stderr)
    if bad:
        sys.exit(1)


def print_header():
    """The table's header (campanile_segment.py prints rows of the same table)."""
    print("| scene | points | method | parameters | time (s) | load before → after | right | under | over | "
          "missed | boundary within 2 cm, mean / p95 (cm) | segments |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")


def print_row(scene, points, method, params, seconds, before, after, m):
    """One method's row (stdout) from its metrics `m`, and the surfaces
    behind its under, over and missed counts (stderr)."""
    b = "none" if m["boundary"] is None else f"{100 * m['boundary'][0]:.1f} %, {m['boundary'][1]:.1f} / {m['boundary'][2]:.1f}"
    print(f"| {scene} | {points} | {method} | {params} | {seconds} | {before} → {after} | "
          f"{100 * m['right']:.1f} % | {m['under']}/{m['counted']} | {m['over']}/{m['counted']} | "
          f"{m['missed']}/{m['counted']} | {b} | {m['segments']} |", flush=True)
    print(f"#   {scene} {method.split(' ')[0]}: under: {m['under_names']}; over: {m['over_names']}; "
          f"missed: {m['missed_names']}; {m['true_boundary']} points next to a true boundary", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog="example: python open3d_segment.py /tmp/scans room --methods ransac")
    ap.add_argument("scandir", type=Path)
    ap.add_argument("set", choices=sorted(PARAMETERS))
    ap.add_argument("--methods", default="ransac,patches")
    ap.add_argument("--header", action="store_true", help="print the table's header first")
    ap.add_argument("--check-metrics", action="store_true",
                    help="check the metrics on known answers (the truth, one segment, nothing) first")
    args = ap.parse_args()
    xyz, truth, surfaces = read_set(args.scandir, args.set)
    if args.check_metrics:
        check_metrics(xyz, truth, surfaces)
    p = PARAMETERS[args.set]
    spacing, _ = cKDTree(xyz).query(xyz[:: max(1, len(xyz) // 20000)], k=2, workers=-1)
    p["voxel"] = float(np.percentile(spacing[:, 1], 99))
    p["eps"] = EPS_VOXELS * p["voxel"]
    print(f"# {args.set}: {len(xyz)} points, {len(surfaces)} true surfaces, {np.count_nonzero(truth < 0)} mixed; "
          f"nearest-neighbour spacing median {100 * np.median(spacing[:, 1]):.2f} cm, "
          f"p90 {100 * np.percentile(spacing[:, 1], 90):.2f} cm, p99 {100 * p['voxel']:.2f} cm; Open3D {o3d.__version__}, "
          f"{o3d.utility.get_num_threads() if hasattr(o3d.utility, 'get_num_threads') else os.cpu_count()} threads",
          file=sys.stderr)
    if args.header:
        print_header()
    for method in args.methods.split(","):
        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))
        before = loadavg()
        clock = time.perf_counter()
        if method == "ransac":
            found, what = ransac_planes(pcd, p)
            params = (f"segment_plane d {100 * p['distance']:g} cm, {p['iterations']} iter, min {p['min_plane']} pts; "
                      f"cluster_dbscan on {100 * p['voxel']:.3g} cm voxels, eps {100 * p['eps']:.3g} cm, min {p['dbscan_min']}")
        elif method == "patches":
            found, what = planar_patches(pcd, p)
            params = (f"estimate_normals hybrid r {100 * p['normal_radius']:g} cm, {p['normal_nn']} nn; "
                      "detect_planar_patches defaults (60°, 75°, 0.75), knn 30")
        else:
            sys.exit(f"--methods {method!r}: expected ransac or patches")
        seconds = time.perf_counter() - clock
        after = loadavg()
        print_row(args.set, len(xyz), f"{method} ({what})", params, f"{seconds:.1f}", before, after,
                  metrics(xyz, truth, found, surfaces))


if __name__ == "__main__":
    main()
