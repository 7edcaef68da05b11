"""Independent check of `campanile texture` (thesis §3.4): Mitsuba 3 loads the
textured OBJ (its own OBJ reader; the MTL's `map_Kd` read here to find each
page, whose linear values are the `page_N.exr` beside the PNG it names) with
each page's texels as the emitted radiance of its triangles, renders the
check view's camera, and compares with the simulator's noise-free render of
that view. Nothing here is Campanile code: the OBJ, MTL and EXR files are the
only link.

    python mitsuba_view.py TEXTURED_DIR FIXTURE_DIR

Prints the figures over the pixels that show a textured surface (Mitsuba's
render non-zero there, eroded by one pixel so that silhouettes, where the two
renderers' pixel filters differ, do not count).
"""

import json
import os
import sys
import tempfile

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def pages_of(textured):
    """Per material of model.mtl: the EXR page its map_Kd PNG stands for."""
    pages, name = {}, None
    with open(os.path.join(textured, "model.mtl")) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "newmtl":
                name = w[1]
            elif w[0] == "map_Kd" and name is not None:
                png = w[-1]
                pages[name] = os.path.join(textured, os.path.splitext(png)[0] + ".exr")
    return pages


def split_obj(textured, out_dir):
    """model.obj split by `usemtl` (Mitsuba's OBJ reader ignores materials):
    every file keeps all v/vt/vn lines and only its material's faces."""
    header, faces, current = [], {}, None
    with open(os.path.join(textured, "model.obj")) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] in ("v", "vt", "vn"):
                header.append(line)
            elif w[0] == "usemtl":
                current = w[1]
            elif w[0] == "f":
                faces.setdefault(current, []).append(line)
    files = {}
    for name, fs in faces.items():
        path = os.path.join(out_dir, f"{name}.obj")
        with open(path, "w") as f:
            f.writelines(header)
            f.writelines(fs)
        files[name] = path
    return files


def main():
    textured, fixture = sys.argv[1], sys.argv[2]
    cam = json.load(open(os.path.join(fixture, "check-camera.json")))
    pages = pages_of(textured)
    tmp = tempfile.mkdtemp()
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 1},
        "sensor": {
            "type": "perspective",
            "fov": cam["vfov_deg"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["position"], target=cam["target"], up=cam["up"]
            ),
            "film": {
                "type": "hdrfilm",
                "width": cam["width"],
                "height": cam["height"],
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": 64},
        },
    }
    for name, path in split_obj(textured, tmp).items():
        scene[name] = {
            "type": "obj",
            "filename": path,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.0}},
            "emitter": {
                "type": "area",
                "radiance": {"type": "bitmap", "filename": pages[name], "filter_type": "bilinear", "raw": True},
            },
        }
    img = np.array(mi.render(mi.load_dict(scene)))[:, :, :3]
    ref = np.array(mi.Bitmap(os.path.join(fixture, "check.exr")))[:, :, :3]
    on = np.all(img > 0, axis=2)
    eroded = on.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            eroded &= np.roll(np.roll(on, dy, axis=0), dx, axis=1)
    eroded[0, :] = eroded[-1, :] = eroded[:, 0] = eroded[:, -1] = False
    a, b = img[eroded], ref[eroded]
    mse = np.mean((a - b) ** 2)
    peak = b.max()
    rel = np.abs(a - b).mean(axis=1) / np.maximum(b.mean(axis=1), 1e-12)
    rms_rel = np.sqrt(np.mean((a - b) ** 2)) / b.mean()
    print(
        f"pixels compared: {eroded.sum()} of {on.size}; PSNR {10 * np.log10(peak * peak / mse):.2f} dB; "
        f"relative RMS {100 * rms_rel:.2f}%; median relative error {100 * np.median(rel):.2f}%; "
        f"mean ratio Mitsuba/simulator {a.mean() / b.mean():.4f}"
    )
    mi.Bitmap(img).write(os.path.join(textured, "mitsuba-check.exr"))


if __name__ == "__main__":
    main()
