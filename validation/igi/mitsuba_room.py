"""A Mitsuba 3 reference room for `campanile igi` (issue 24): a second
renderer, independent of RADIANCE and of Campanile.

    python mitsuba_room.py OUT_DIR [--size 64] [--spp 4096]

A 3 x 3.5 x 2.4 m box room path traced by Mitsuba 3 (`scalar_rgb`,
`path`, max_depth 12, Russian roulette from depth 5 (unbiased)) with
Lambertian faces (`diffuse`, one with a `bitmap` checker) and Ward-like
faces written as Campanile's Mitsuba export writes a Ward material: a
`blendbsdf` of `diffuse` (rho_d / (1 - w)) and a Beckmann `roughconductor`
with `material none` (rho_s / w), w = sum rho_s / sum (rho_d + rho_s).
That lobe is Ward with Duer's (2006) normalization times Smith's G
(process/src/material_export/mitsuba.rs), so truth.json says
variant "Duer" and notes that G makes it approximate near grazing.

Lights are `sphere` shapes with an `area` emitter of radiance L; the
intensity Campanile is given is I = L pi r^2 W/sr. Each view is the mean of
two renders with different seeds (spp / 2 each); their difference gives
the noise (render.json).

Writes OUT_DIR/mitsuba-interreflection/: room.obj (Campanile's geometry;
Mitsuba loads the same quads from mitsuba/<face>.obj, which carry the
texture coordinates), mitsuba/checker.exr, views/<view>.exr, masks,
scene.ron (hfov_deg cameras, Known lights, ward_variant Duer),
scene-exr.ron (older form: vfov_deg), truth.json, render.json.
"""

import argparse
import math
import shutil
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import room as R  # noqa: E402

SIZE = (3.0, 3.5, 2.4)
CHECKER = {"face": "wall_south", "squares": (5, 4), "a": (0.70, 0.68, 0.62), "b": (0.25, 0.35, 0.55)}
FACES = {
    # rho_d, rho_s, alpha (None: Lambertian)
    "floor": {"rho_d": (0.40, 0.33, 0.26), "rho_s": (0.05, 0.05, 0.05), "alpha": 0.12},
    "ceiling": {"rho_d": (0.78, 0.78, 0.76), "rho_s": None, "alpha": None},
    "wall_south": {"rho_d": None, "rho_s": None, "alpha": None},  # the bitmap checker
    "wall_north": {"rho_d": (0.28, 0.42, 0.52), "rho_s": (0.06, 0.06, 0.06), "alpha": 0.08},
    "wall_west": {"rho_d": (0.58, 0.52, 0.44), "rho_s": None, "alpha": None},
    "wall_east": {"rho_d": (0.45, 0.45, 0.45), "rho_s": (0.04, 0.04, 0.04), "alpha": 0.15},
}
LIGHTS = [
    {"name": "m1", "position": (0.9, 1.2, 2.1), "radius": 0.02, "intensity": (2.0, 1.8, 1.5)},
    {"name": "m2", "position": (2.2, 2.5, 2.0), "radius": 0.02, "intensity": (1.2, 1.5, 1.9)},
    {"name": "m3", "position": (1.6, 0.9, 1.3), "radius": 0.02, "intensity": (0.8, 0.8, 0.8)},
]


def bsdf_dict(face):
    m = FACES[face]
    if face == CHECKER["face"]:
        return {"type": "diffuse", "reflectance": {"type": "bitmap", "filename": "mitsuba/checker.exr", "filter_type": "nearest", "raw": True}}
    if m["rho_s"] is None:
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(m["rho_d"])}}
    d, s = np.array(m["rho_d"]), np.array(m["rho_s"])
    w = s.sum() / (d + s).sum()
    return {
        "type": "blendbsdf",
        "weight": float(w),
        "a": {"type": "diffuse", "reflectance": {"type": "rgb", "value": (d / (1 - w)).tolist()}},
        "b": {
            "type": "roughconductor",
            "material": "none",
            "distribution": "beckmann",
            "alpha": m["alpha"],
            "specular_reflectance": {"type": "rgb", "value": (s / w).tolist()},
        },
    }


def write_face_obj(path, face):
    c = R.face_corners(face, SIZE)
    lines = [f"o {face}"] + ["v {:.6f} {:.6f} {:.6f}".format(*p) for p in c]
    lines += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1", "f 1/1 2/2 3/3", "f 1/1 3/3 4/4"]
    path.write_text("\n".join(lines) + "\n")


def checker_image():
    nu, nv = CHECKER["squares"]
    img = np.zeros((nv, nu, 3), np.float32)
    for j in range(nv):
        for i in range(nu):
            img[j, i] = CHECKER["a"] if (i + j) % 2 == 0 else CHECKER["b"]
    return img


def views(size_px):
    """Four wide views from the upper corners, and highlight views for the
    three glossy faces (two lamps each), placed as generate.py does."""
    import generate

    room = {
        "name": "mitsuba",
        "size": SIZE,
        "lights": LIGHTS,
        "faces": {f: {"spec": 0.0 if FACES[f]["rho_s"] is None else FACES[f]["rho_s"][0]} for f in FACES},
    }
    hl, _ = generate.highlight_views(room, size_px)
    return generate.wide_views(room, size_px) + hl


def scene_dict(mi, view, spp):
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 12, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": view.hfov_deg,
            "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=view.position.tolist(), target=(view.position + view.direction).tolist(), up=[0, 0, 1]
            ),
            "film": {"type": "hdrfilm", "width": view.width, "height": view.height, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    for face in FACES:
        d[face] = {"type": "obj", "filename": f"mitsuba/{face}.obj", "face_normals": True, "bsdf": bsdf_dict(face)}
    for light in LIGHTS:
        L = [i / (math.pi * light["radius"] ** 2) for i in light["intensity"]]
        d[light["name"]] = {
            "type": "sphere",
            "center": list(light["position"]),
            "radius": light["radius"],
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": L}},
        }
    return d


def truth():
    out = {
        "room": "mitsuba",
        "variant": "Duer",
        "mode": "interreflection",
        "note": "Mitsuba's roughconductor (Beckmann, material none) is Ward with Duer's normalization times Smith's G; G < 1 toward grazing, so the truth is approximate there",
        "surfaces": [],
    }
    for face, m in FACES.items():
        e = {"name": face, "variant": "Duer"}
        if face == CHECKER["face"]:
            nu, nv = CHECKER["squares"]
            frac_a = math.ceil(nu * nv / 2) / (nu * nv)
            a, b = np.array(CHECKER["a"]), np.array(CHECKER["b"])
            e.update(model="diffuse", rho_d=(frac_a * a + (1 - frac_a) * b).round(9).tolist(), rho_s=[0.0] * 3)
            e.update(alpha_x=None, alpha_y=None, gamma_deg=None)
            e["texture"] = {
                "kind": "checker",
                "squares_u_v": [nu, nv],
                "rho_d_a": list(CHECKER["a"]),
                "rho_d_b": list(CHECKER["b"]),
                "fraction_a": frac_a,
                "rule": "a bitmap of nu x nv texels (nearest), texel (i, j) is a where i + j is even; u runs along the face's first edge in room.obj",
            }
        elif m["rho_s"] is None:
            e.update(model="diffuse", rho_d=list(m["rho_d"]), rho_s=[0.0] * 3, alpha_x=None, alpha_y=None, gamma_deg=None)
        else:
            e.update(model="isotropic plastic", rho_d=list(m["rho_d"]), rho_s=list(m["rho_s"]))
            e.update(alpha_x=m["alpha"], alpha_y=m["alpha"], gamma_deg=0.0)
        out["surfaces"].append(e)
    return out


def scene_ron(vs, exr):
    header = [] if exr else ["    ward_variant: Some(Duer),", "    interreflection: Some(true),"]
    return R.exr_scene_ron(vs, LIGHTS, header, fov_key="vfov_deg" if exr else "hfov_deg")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out", type=Path)
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    if a.threads > 1:
        dr.set_thread_count(a.threads)
    d = a.out / "mitsuba-interreflection"
    if d.exists():
        shutil.rmtree(d)
    for sub in ("views", "masks", "mitsuba"):
        (d / sub).mkdir(parents=True)
    R.write_obj(d / "room.obj", SIZE, list(FACES))
    for face in FACES:
        write_face_obj(d / "mitsuba" / f"{face}.obj", face)
    mi.Bitmap(checker_image()).write(str(d / "mitsuba" / "checker.exr"))
    mi.file_resolver().prepend(str(d))
    vs = views(a.size)
    rel = []
    t0 = time.time()
    for v in vs:
        scene = mi.load_dict(scene_dict(mi, v, a.spp // 2))
        imgs = [np.array(mi.render(scene, seed=s), dtype=np.float64)[..., :3] for s in (1, 2)]
        rgb = (imgs[0] + imgs[1]) / 2
        mask = R.light_mask(v, LIGHTS, dilate=1)
        mi.Bitmap(rgb.astype(np.float32)).write(str(d / "views" / f"{v.name}.exr"))
        R.write_png_gray(d / "masks" / f"{v.name}.png", mask)
        s = rgb.sum(axis=2)
        sig = np.abs(imgs[0] - imgs[1]).sum(axis=2) / 2 * math.sqrt(math.pi / 2)
        m = (mask > 0) & (s > 0)
        rel.append(sig[m] / s[m])
        print(f"  mitsuba {v.name}: {time.time() - t0:.1f} s", flush=True)
    rel = np.concatenate(rel)
    (d / "scene.ron").write_text(scene_ron(vs, exr=False))
    (d / "scene-exr.ron").write_text(scene_ron(vs, exr=True))
    R.write_json(d / "truth.json", truth())
    R.write_json(
        d / "render.json",
        {
            "mitsuba": mi.__version__,
            "variant": "scalar_rgb",
            "integrator": "path, max_depth 12, rr_depth 5",
            "film": "hdrfilm, box reconstruction filter (each pixel the mean over its area)",
            "spp": a.spp,
            "seconds": round(time.time() - t0, 1),
            "noise": {
                "median_rel_sigma": round(float(np.median(rel)), 5),
                "p90_rel_sigma": round(float(np.percentile(rel, 90)), 5),
                "method": "each view is the mean of two renders (seeds 1, 2; spp/2 each); per pixel sigma of the mean = |a - b| / 2 sqrt(pi/2), R+G+B, over R+G+B of the mean",
            },
        },
    )
    print(f"{d}: {time.time() - t0:.1f} s, median noise {np.median(rel):.4f}")


if __name__ == "__main__":
    main()
