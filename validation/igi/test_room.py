"""Self-tests of the reference writers (run by generate.sh after generating):
the gamma convention against hand-derived cases, RGBE round trip against
the files rpict wrote, and the light masks.

    python test_room.py [OUT_DIR]
"""

import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import room as R  # noqa: E402


def test_gamma_convention():
    # Floor (normal +z): t = +y (north), s = t x n = +x, b = n x s = +y.
    s, b = R.campanile_tangent_frame((0, 0, 1))
    assert np.allclose(s, (1, 0, 0)) and np.allclose(b, (0, 1, 0)), (s, b)
    u = (math.cos(math.radians(30)), math.sin(math.radians(30)), 0)
    assert np.allclose(R.canonical_gamma(0.18, 0.07, u, (0, 0, 1)), (0.18, 0.07, 30.0))
    # v = n x u is 90 deg further: the wider v axis gives gamma + 90, folded into (-90, 90].
    assert np.allclose(R.canonical_gamma(0.07, 0.18, u, (0, 0, 1)), (0.18, 0.07, -60.0))
    # Ceiling (normal -z): s = +y x -z = -x, b = n x s = +y.
    s, b = R.campanile_tangent_frame((0, 0, -1))
    assert np.allclose(s, (-1, 0, 0)) and np.allclose(b, (0, 1, 0)), (s, b)
    # West wall (normal +x): t = +z, s = z x x = +y, b = +z; u = (0, 1, 1) is at 45 deg.
    assert np.allclose(R.canonical_gamma(0.16, 0.06, (0, 1, 1), (1, 0, 0)), (0.16, 0.06, 45.0))
    # East wall (normal -x): s = -y, b = +z; u = +z is at 90 deg.
    assert np.allclose(R.canonical_gamma(0.14, 0.07, (0, 0, 1), (-1, 0, 0)), (0.14, 0.07, 90.0))
    # A u vector with a normal component is projected first (aniso.c getacoords).
    assert np.allclose(R.canonical_gamma(0.14, 0.07, (0, 0.3, 1), (-1, 0, 0))[2], 90 + math.degrees(math.atan2(0.3, 1)) - 180)


def test_faces_point_inward():
    size = (4.0, 3.0, 2.6)
    centre = np.array(size) / 2
    for f in R.FACE_NAMES:
        c = np.array(R.face_corners(f, size), float)
        n = R.normal_of(c)
        assert np.dot(centre - c.mean(0), n) > 0, f


def test_rgbe_roundtrip(tmp):
    rng = np.random.default_rng(1)
    img = (rng.random((7, 9, 3)) * 10 ** rng.uniform(-3, 3, (7, 9, 1))).astype(np.float32)
    p = tmp / "rt.hdr"
    R.write_rgbe(p, img)
    back = R.read_rgbe(p)
    rel = np.abs(back - img) / img.max(axis=2, keepdims=True)
    assert rel.max() < 1 / 128, rel.max()
    p.unlink()


def test_masks(out):
    for scene in sorted(out.glob("*/truth.json")):
        d = scene.parent
        for m in sorted((d / "masks").glob("*.png")):
            assert m.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", m
        views = sorted((d / "views").iterdir())
        assert len(views) == len(list((d / "masks").glob("*.png"))), d
        truth = json.loads(scene.read_text())
        assert truth["surfaces"] and all("rho_d" in s for s in truth["surfaces"]), scene


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else None
    test_gamma_convention()
    test_faces_point_inward()
    tmp = out if out else Path("/tmp")
    test_rgbe_roundtrip(tmp)
    if out:
        test_masks(out)
    print("test_room.py: all checks pass")


if __name__ == "__main__":
    main()
