"""Fig. 4's numbers against the paper's closed form, computed here.

GGX (normalised so that the integral of D (h.n) over the hemisphere is 1)
has the polar CDF ``c(theta) = tan^2 / (alpha^2 + tan^2)``, so its median angle
is ``atan(alpha)``. Scaling the lobe by ``s`` in its inverse-CDF space scales
every quantile angle: ``theta'(y) = s theta(y)``; quantiles past pi/2 are
dropped and the rest renormalised, so the new CDF is
``c(theta / s) / c(pi / (2 s))`` and the median solves
``c(theta' / s) = c(pi / (2 s)) / 2``. None of this uses matshop.
"""

from __future__ import annotations

import math

import pytest

from matshop.figures import make_figures

ALPHA = 0.15  # the figure's lobe


def ggx_cdf(theta: float) -> float:
    t2 = math.tan(theta) ** 2
    return t2 / (ALPHA**2 + t2)


def scaled_median(s: float) -> float:
    kept = ggx_cdf(min(math.pi / 2, math.pi / (2 * s))) if s > 1 else 1.0
    half = 0.5 * kept
    # invert c: tan^2 = half alpha^2 / (1 - half)
    return s * math.atan(ALPHA * math.sqrt(half / (1 - half)))


def test_fig4_scaled_medians_follow_the_closed_form(tmp_path) -> None:
    values = make_figures(tmp_path, only=["fig4"])[0].values
    median = math.atan(ALPHA)
    for s in (0.75, 1.5):
        want = scaled_median(s) / median
        # 128 bins of pi/256: the binned median is good to a small fraction of a bin
        assert values[f"ratio_s{s:g}"] == pytest.approx(want, abs=0.004), s
    # the renormalisation is visible at s = 1.5: not the plain factor 1.5
    assert scaled_median(1.5) / median < 1.495
