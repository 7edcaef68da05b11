"""Traces the rays that `cargo bench -p campanile-sim --bench rays` dumped
(CAMPANILE_RAYS_DUMP=DIR) with Mitsuba 3 on the same triangles, and prints
the same table: Mrays/s for primary, shadow (any hit) and diffuse-bounce
rays, with the hit fraction as a check that both traced the same rays.

Mitsuba's `llvm_ad_rgb` variant traces through Embree (the wheels build it
with Embree) on all cores, wavefront style: one call for all the rays. This
is the "Embree-class traversal" issue 30 measures against. Its `scalar_rgb`
variant (Mitsuba's own kd-tree, one ray per call) is timed on a sample of
rays, for a per-ray figure; from Python, its call overhead dominates.

    python peer.py DIR
"""

import os
import sys
import time
from pathlib import Path

import numpy as np

for cand in ("/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"):
    if "DRJIT_LIBLLVM_PATH" not in os.environ and Path(cand).exists():
        os.environ["DRJIT_LIBLLVM_PATH"] = cand

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402


def write_ply(tris, path):
    """The dumped triangles (9 floats each) as a binary PLY, unshared corners."""
    n = len(tris) // 9
    with open(path, "wb") as f:
        f.write(
            f"ply\nformat binary_little_endian 1.0\nelement vertex {3 * n}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element face {n}\nproperty list uchar int vertex_indices\nend_header\n".encode()
        )
        f.write(tris.astype("<f4").tobytes())
        faces = np.zeros(n, dtype=[("n", "u1"), ("i", "<i4", 3)])
        faces["n"] = 3
        faces["i"] = np.arange(3 * n, dtype="<i4").reshape(n, 3)
        f.write(faces.tobytes())


def mesh(ply):
    return mi.load_dict({"type": "scene", "mesh": {"type": "ply", "filename": str(ply), "face_normals": True}})


def main(dump):
    print("| scene | rays | query | peer | Mrays/s | hits |")
    print("|---|---|---|---|---|---|")
    for stem in ("campanile", "room"):
        tris = np.fromfile(dump / f"{stem}-triangles.f32", dtype="<f4")
        ply = dump / f"{stem}.ply"
        write_ply(tris, ply)
        for kind in ("primary", "shadow", "diffuse-bounce"):
            r = np.fromfile(dump / f"{stem}-{kind}.f32", dtype="<f4").reshape(-1, 7)
            query = "any hit" if kind == "shadow" else "nearest"
            mi.set_variant("llvm_ad_rgb")
            scene = mesh(ply)
            o = mi.Point3f(*(r[:, i].copy() for i in range(3)))
            d = mi.Vector3f(*(r[:, i].copy() for i in range(3, 6)))
            ray = mi.Ray3f(o, d)
            ray.maxt = mi.Float(r[:, 6].copy())
            best, hits = float("inf"), 0
            for _ in range(4):
                dr.eval(ray)
                dr.sync_thread()
                t0 = time.perf_counter()
                if query == "nearest":
                    hit = scene.ray_intersect_preliminary(ray, coherent=(kind == "primary")).is_valid()
                else:
                    hit = scene.ray_test(ray)
                count = dr.count(hit)
                dr.eval(count)
                dr.sync_thread()
                best = min(best, time.perf_counter() - t0)
                hits = int(count[0] if hasattr(count, "__len__") else count)
            n = len(r)
            print(f"| {stem} | {n} {kind} | {query} | mitsuba {mi.__version__} llvm_ad_rgb (Embree) | {n / best / 1e6:.2f} | {100 * hits / n:.1f}% |")
            # scalar_rgb: one ray per Python call, on 20 000 rays.
            mi.set_variant("scalar_rgb")
            scene = mesh(ply)
            sample = r[:: max(1, len(r) // 20000)]
            t0 = time.perf_counter()
            hits = 0
            for row in sample:
                ray = mi.Ray3f(mi.Point3f(*row[:3]), mi.Vector3f(*row[3:6]))
                ray.maxt = float(row[6])
                if query == "nearest":
                    hits += scene.ray_intersect_preliminary(ray).is_valid()
                else:
                    hits += scene.ray_test(ray)
            s = time.perf_counter() - t0
            print(f"| {stem} | {len(sample)} {kind} (sample) | {query} | mitsuba scalar_rgb, one thread, per Python call | {len(sample) / s / 1e6:.2f} | {100 * hits / len(sample):.1f}% |")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
