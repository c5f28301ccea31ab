"""Fit the polynomials of the Phong median-angle kernels (``matshop/spaces/_kernels.py``).

    python scripts/fit_phong_median.py      (needs mpmath)

The median angle of ``cos^n`` is ``e = acos(2^(-1/(n+2)))``; with ``x = 1/(n+2)``
both directions factor into a closed part the kernels evaluate exactly and a
smooth part fitted here:

- to the edit space: ``e = sqrt(x) G(x)`` on ``x`` in [0, 1/2] (``G(0) = sqrt(2 ln 2)``);
- back: ``n = S(e) (pi/4 - e) / e^2`` on ``e`` in [0, pi/4], the factor
  ``pi/4 - e`` holding the zero at ``n = 0`` (so no difference of nearly equal
  numbers is left near it) and ``1/e^2`` the pole at ``n = inf``.

Each is a least-squares fit of the relative error on Chebyshev nodes, reweighted
towards the least largest error (Lawson), to 50-digit values; the script prints
the coefficients and the largest relative error on a dense grid.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np

mp.mp.dps = 50
QUARTER_PI = mp.pi / 4


def g_of_x(x: float) -> mp.mpf:
    x = mp.mpf(x)
    if x == 0:
        return mp.sqrt(2 * mp.log(2))
    return 2 * mp.asin(mp.sqrt((1 - mp.power(2, -x)) / 2)) / mp.sqrt(x)


def s_of_e(e: float) -> mp.mpf:
    e = mp.mpf(e)
    if e == 0:
        return 2 * mp.log(2) / QUARTER_PI
    if abs(e - QUARTER_PI) < mp.mpf(10) ** -30:
        return 4 / mp.log(2) * QUARTER_PI**2  # -dn/de at pi/4 times e^2
    n = -mp.log(2) / mp.log(mp.cos(e)) - 2
    return n * e**2 / (QUARTER_PI - e)


def fit(function, degree: int, hi: float, nodes: int = 500) -> tuple[list[float], float]:
    """Coefficients (lowest first) for the least largest relative error on [0, hi]."""
    k = np.arange(nodes)
    x = hi / 2 - hi / 2 * np.cos((2 * k + 1) * np.pi / (2 * nodes))
    values = np.array([float(function(t)) for t in x])
    basis = np.vander(x, degree + 1, increasing=True) / values[:, None]
    weight = np.full(nodes, 1.0 / nodes)
    for _ in range(40):
        coeffs, *_ = np.linalg.lstsq(basis * np.sqrt(weight)[:, None], np.sqrt(weight), rcond=None)
        weight *= np.abs(basis @ coeffs - 1.0) + 1e-30
        weight /= weight.sum()
    worst = 0.0
    for t in np.linspace(0.0, hi, 2001):
        exact = function(t)
        approx = mp.fsum(mp.mpf(float(c)) * mp.mpf(t) ** i for i, c in enumerate(coeffs))
        worst = max(worst, abs(float((approx - exact) / exact)))
    return [float(c) for c in coeffs], worst


def main() -> None:
    for name, function, degree, hi in (
        ("_PHONG_G (e = sqrt(x) G(x))", g_of_x, 7, 0.5),
        ("_PHONG_S (n = S(e) (pi/4 - e) / e^2)", s_of_e, 12, float(QUARTER_PI)),
    ):
        coeffs, worst = fit(function, degree, hi)
        print(f"{name}: degree {degree}, largest relative error {worst:.2g}")
        print("    " + ",\n    ".join(repr(c) for c in coeffs))


if __name__ == "__main__":
    main()
