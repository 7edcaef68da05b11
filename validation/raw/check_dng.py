#!/usr/bin/env python3
"""Decode the DNG fixtures with LibRaw (through rawpy) and write what it reports.

For each validation/raw/fixtures/NAME.dng, writes NAME.rawpy.csv with rows
"kind,x,y,c,value":

- raw: raw_image value at (x, y), on a fixed grid of 48 photosites;
- raw_color: LibRaw's colour index (0 R, 1 G, 2 B, 3 G2) of the top-left 2x2;
- black: black_level_per_channel[c]; white: white_level;
- cam_wb: camera_whitebalance[c]; rgb_cam: color_matrix[x][y] (camera -> sRGB,
  computed by LibRaw from the file's ColorMatrix1 the way dcraw does);
- post: postprocess(gamma=(1, 1), no_auto_bright=True, output_bps=16,
  use_camera_wb=True, output_color=raw, adjust_maximum_thr=0) at (x, y, c),
  at the centre of each 16x16 patch; post_size: its width and height.

Run with a venv outside the repository:
    venv=$(bench/venv.sh rawpy numpy); "$venv/bin/python" validation/raw/check_dng.py
"""
import csv
import pathlib
import sys

import rawpy

HERE = pathlib.Path(__file__).resolve().parent
FIXTURES = HERE / "fixtures"


def main() -> int:
    files = sorted(FIXTURES.glob("*.dng"))
    if not files:
        print(f"no DNG in {FIXTURES}", file=sys.stderr)
        return 2
    print(f"rawpy {rawpy.__version__}, LibRaw {rawpy.libraw_version}")
    for path in files:
        rows = []
        with rawpy.imread(str(path)) as r:
            raw = r.raw_image
            h, w = raw.shape
            for y in range(1, h, 11):
                for x in range(2, w, 13):
                    rows.append(("raw", x, y, 0, int(raw[y, x])))
            colors = r.raw_colors
            for y in range(2):
                for x in range(2):
                    rows.append(("raw_color", x, y, 0, int(colors[y, x])))
            for c, b in enumerate(r.black_level_per_channel):
                rows.append(("black", 0, 0, c, int(b)))
            rows.append(("white", 0, 0, 0, int(r.white_level)))
            for c, v in enumerate(r.camera_whitebalance):
                rows.append(("cam_wb", 0, 0, c, float(v)))
            m = r.color_matrix
            for i in range(m.shape[0]):
                for j in range(m.shape[1]):
                    rows.append(("rgb_cam", i, j, 0, float(m[i][j])))
            post = r.postprocess(
                gamma=(1, 1),
                no_auto_bright=True,
                output_bps=16,
                use_camera_wb=True,
                output_color=rawpy.ColorSpace.raw,
                adjust_maximum_thr=0.0,
            )
            ph, pw, _ = post.shape
            rows.append(("post_size", pw, ph, 0, 0))
            for py in range(8, ph, 16):
                for px in range(8, pw, 16):
                    for c in range(3):
                        rows.append(("post", px, py, c, int(post[py, px, c])))
        out = path.with_suffix(".rawpy.csv")
        with open(out, "w", newline="") as f:
            wr = csv.writer(f)
            wr.writerow(["kind", "x", "y", "c", "value"])
            wr.writerows(rows)
        print(f"wrote {out.relative_to(HERE.parent.parent)} ({len(rows)} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
