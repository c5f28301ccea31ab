"""all_finite against numpy's elementwise test, on the cases its sum shortcut could get wrong."""

import numpy as np
import pytest

from matshop.finite import all_finite


def _cases():
    rng = np.random.default_rng(7)
    values = rng.normal(size=(64, 48, 8)).astype(np.float32)
    yield "plain", values
    yield "finite values whose sum overflows", np.full((256, 3), 3e38, np.float32)
    yield "float16 summing past 65504", np.full(100, 60000.0, np.float16)
    for bad in (np.nan, np.inf, -np.inf):
        for where in [(0, 0, 0), (63, 47, 7), (31, 20, 3)]:
            hit = values.copy()
            hit[where] = bad
            yield f"{bad} at {where}", hit
    both = values.copy()
    both[1, 1, 1], both[2, 2, 2] = np.inf, -np.inf  # cancel to NaN, not to a finite sum
    yield "+inf and -inf", both
    big = np.full((256, 3), 3e38, np.float32)
    big[100, 1] = np.nan
    yield "NaN among overflowing values", big
    yield "strided view", values[::3, 1::2, 2:5]
    strided_bad = values.copy()
    strided_bad[3, 1, 2] = np.nan
    yield "strided view over a NaN", strided_bad[::3, 1::2, 2:5]
    yield "float64", rng.normal(size=1000)
    yield "integers", np.arange(10, dtype=np.int64)
    yield "booleans", np.ones(5, bool)
    yield "empty", np.empty((0, 3), np.float32)


CASES = list(_cases())


@pytest.mark.parametrize(("name", "values"), CASES, ids=[name for name, _ in CASES])
def test_all_finite_agrees_with_the_elementwise_test(name, values):
    assert all_finite(values) == bool(np.isfinite(values).all()), name
