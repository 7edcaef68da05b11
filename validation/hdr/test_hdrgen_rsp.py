#!/usr/bin/env python3
"""The maker's curve as committed (fixtures/radiantlab-eos/curves/*/hdrgen_rsp.csv)
and as hdrgen_rsp.py computes it must be the .rsp evaluated the way hdrgen
evaluates it (panlib phdrimg: x = (code + 0.5)/256; codes below 19 on the
line through zero). Known answers below are computed by hand from the
file's coefficients, not by hdrgen_rsp.py.

    python3 -m unittest validation/hdr/test_hdrgen_rsp.py
"""

import csv
import math
import pathlib
import sys
import unittest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import hdrgen_rsp  # noqa: E402

FX = HERE / "fixtures" / "radiantlab-eos"
# Response_function.rsp, highest power first.
RED = [2.48363666666666, -2.57911666666665, 1.00832766666665, 0.0852399666666787, 0.00191103299999811]
BLUE = [3.17448333333332, -3.61331666666663, 1.40380333333329, 0.0321496266666864, 0.00287970333333048]


def poly(coef, x):
    return sum(c * x ** (len(coef) - 1 - k) for k, c in enumerate(coef))


# Blue at code 128: x = 128.5/256 (code/255 would give ln −2.1433361).
B128 = math.log(poly(BLUE, 128.5 / 256))
# Red at code 10: on the toe, (10.5/256)/(19.5/256) · f_R(19.5/256)
# (the polynomial at 10/255 would give ln −5.0124192).
R10 = math.log(10.5 / 19.5 * poly(RED, 19.5 / 256))
TOL = 1e-7


def fixture(path):
    rows = [ln for ln in path.read_text().splitlines() if ln and not ln.startswith("#")]
    return {int(r["code"]): r for r in csv.DictReader(rows)}


class HdrgenRsp(unittest.TestCase):
    def test_known_answers_are_hdrgens(self):
        self.assertAlmostEqual(B128, -2.1433567081, delta=1e-9)
        self.assertAlmostEqual(R10, -4.9467188268, delta=1e-9)

    def test_reader(self):
        ln = hdrgen_rsp.ln_curve(FX / "Response_function.rsp")
        self.assertAlmostEqual(ln[128][2], B128, delta=TOL)
        self.assertAlmostEqual(ln[10][0], R10, delta=TOL)

    def test_committed_curves(self):
        for which in ("full", "crop"):
            rows = fixture(FX / "curves" / which / "hdrgen_rsp.csv")
            with self.subTest(which=which):
                self.assertAlmostEqual(float(rows[128]["ln_exposure_b"]), B128, delta=TOL)
                self.assertAlmostEqual(float(rows[10]["ln_exposure_r"]), R10, delta=TOL)


if __name__ == "__main__":
    unittest.main()
