"""The hdrgen response file (`.rsp`) and the curve hdrgen makes of it.

Format (panlib `phdrimg.h`, `operator>>(istream&, PPolynomial&)`, which
hdrgen's `-r cam.rsp` reads): three lines, R, G, B, each
"DEGREE c_DEGREE … c_1 c_0", highest power first; a fitted file's
coefficients sum to 1 (`FindPoly` sets c_0 = 1 − Σ others).

Evaluation (panlib `PHDImageMaker::GetResponse`): the polynomial is taken at
x = PbyteVal(code) = (code + 0.5) / 256, not code / 255; from code 255 down
while the value and its derivative stay positive, but never below code
P_LINRESP = 19: codes under that (or under the first non-positive value)
lie on the line through zero, resp(z) = x(z) · resp(toe) / x(toe).

Standard library only, so compare_curves.py's users need no numpy.
"""

import math

P_LINRESP = 19


def byte_val(code):
    """panlib PbyteVal: 8-bit code -> [0, 1)."""
    return (code + 0.5) / 256.0


def read_rsp(path):
    """[[c_DEGREE, …, c_0] for R, G, B] from an .rsp file (pathlib.Path)."""
    lines = [ln.split() for ln in path.read_text().splitlines() if ln.strip()]
    if len(lines) != 3:
        raise ValueError(f"{path}: expected 3 polynomials (R, G, B), found {len(lines)}")
    polys = []
    for n, parts in enumerate(lines, 1):
        try:
            degree = int(parts[0])
            coef = [float(v) for v in parts[1:]]
        except ValueError as e:
            raise ValueError(f"{path} line {n}: {e}")
        if len(coef) != degree + 1:
            raise ValueError(f"{path} line {n}: degree {degree} needs {degree + 1} coefficients, found {len(coef)}")
        polys.append(coef)
    return polys


def _eval(coef, x):
    r = 0.0
    for c in coef:
        r = r * x + c
    return r


def _deriv(coef, x):
    degree = len(coef) - 1
    r = 0.0
    for k, c in enumerate(coef[:-1]):
        r = r * x + (degree - k) * c
    return r


def response(coef):
    """Relative linear exposure for codes 0..255, as hdrgen computes it."""
    resp = [0.0] * 256
    toe = 256
    while toe > P_LINRESP:
        toe -= 1
        x = byte_val(toe)
        resp[toe] = _eval(coef, x)
        if resp[toe] <= 0 or _deriv(coef, x) <= 0:
            toe += 1
            break
    slope = resp[toe] / byte_val(toe)
    for z in range(toe):
        resp[z] = byte_val(z) * slope
    return resp


def ln_curve(path):
    """[(ln_r, ln_g, ln_b)] for codes 0..255: the .rsp as hdrgen uses it."""
    chans = [[math.log(v) for v in response(coef)] for coef in read_rsp(path)]
    return list(zip(*chans))
