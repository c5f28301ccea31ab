"""Analytic-distribution editing spaces: contract, precision, and the Fig. 5 table.

The table test reproduces MATH.md "Analytic distributions: approximate editing
spaces" with :func:`matshop.spaces.fit.scaling_fit` and checks that each
family's default coordinate is the one :func:`~matshop.spaces.fit.best_coordinate`
picks.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from matshop.spaces import ashikhmin_shirley, beckmann, ggx, lobes, phong
from matshop.spaces.base import EditRange, Space
from matshop.spaces.fit import FAMILIES, Family, best_coordinate, scaling_fit

MODULES = {"phong": phong, "ashikhmin_shirley": ashikhmin_shirley, "beckmann": beckmann, "ggx": ggx}
SPACES: dict[str, Space] = {k: v for m in MODULES.values() for k, v in m.SPACES.items()}

COORDINATE_KEYS = {
    "phong": ["paper", "small_angle", "median"],
    "ashikhmin_shirley": ["paper", "small_angle", "median"],
    "beckmann": ["identity", "median"],
    "ggx": ["alpha", "median"],
}
PAPER = {"phong": "paper", "ashikhmin_shirley": "paper", "beckmann": "identity", "ggx": "alpha"}


def family_of(name: str) -> str:
    return next(f for f in sorted(MODULES, key=len, reverse=True) if name.startswith(f))


# physical domain (lo, hi) per family, and round-trip tolerance |b - a| <= rtol*|a| + atol
DOMAIN = {
    "phong": (0.0, phong.N_MAX),
    "ashikhmin_shirley": (0.0, phong.N_MAX),
    "beckmann": (beckmann.M_MIN, beckmann.M_MAX),
    "ggx": (0.0, 1.0),
}
TOLERANCE = {
    "phong_paper": (1e-6, 0.0),
    "phong_small_angle": (4e-6, 2e-6),
    "phong_median": (4e-6, 2e-6),
    "beckmann_identity": (0.0, 0.0),
    "beckmann_median": (2e-5, 0.0),
    "ggx_alpha": (4e-7, 1e-7),
    "ggx_median": (4e-7, 1e-7),
}


def coordinate_key(name: str) -> str:
    return SPACES[name].coordinate


def tolerance(name: str) -> tuple[float, float]:
    family = family_of(name)
    phong_like = "phong" if family == "ashikhmin_shirley" else family
    return TOLERANCE[f"{phong_like}_{coordinate_key(name)}"]


def domain(name: str) -> tuple[float, float]:
    lo, hi = DOMAIN[family_of(name)]
    if coordinate_key(name) == "paper":
        lo = phong.N_FLOOR_PAPER  # 1/sqrt(0) is infinite; the paper coordinate floors n
    return lo, hi


# the typical range of each family, for relative errors and strict monotonicity
TYPICAL = {
    "phong": (1.0, phong.N_MAX),
    "ashikhmin_shirley": (1.0, phong.N_MAX),
    "beckmann": (0.01, beckmann.M_MAX),
    "ggx": (1.0 / 255.0, 1.0),
}


def dense_grid(name: str) -> np.ndarray:
    lo, hi = domain(name)
    if family_of(name) == "ggx":
        values = np.linspace(0.0, 1.0, 20001)
    else:
        values = np.geomspace(max(lo, 1e-6), hi, 20001)
    values = np.unique(values.astype(np.float32))
    return np.repeat(values[:, None], SPACES[name].phys_channels, axis=1)


# --- registry and contract ----------------------------------------------------------------


def test_registry_names():
    expected = {
        "phong", "phong_paper", "phong_small_angle", "phong_median",
        "ashikhmin_shirley", "ashikhmin_shirley_paper", "ashikhmin_shirley_small_angle",
        "ashikhmin_shirley_median",
        "beckmann", "beckmann_identity", "beckmann_median",
        "ggx", "ggx_alpha", "ggx_median",
    }  # fmt: skip
    assert set(SPACES) == expected
    for family, keys in COORDINATE_KEYS.items():
        assert SPACES[family].coordinate == MODULES[family].DEFAULT_COORDINATE
        for key in keys:
            assert SPACES[f"{family}_{key}"].coordinate == key
            assert SPACES[f"{family}_{key}"].family == family
    for key, space in SPACES.items():
        assert space.name == key
        assert space.curve_mode == "channels"
        assert isinstance(space.edit_range, EditRange) and space.edit_range.span > 0
        assert space.description
        assert space.phys_channels == space.edit_channels == (2 if "ashikhmin" in key else 1)


@pytest.mark.parametrize("name", sorted(SPACES))
def test_float32_shapes_and_input_untouched(name):
    space = SPACES[name]
    lo, hi = domain(name)
    rng = np.random.default_rng(0)
    phys = rng.uniform(lo, min(hi, 50.0), size=(4, 5, space.phys_channels))  # float64 input
    before = phys.copy()
    edit = space.to_edit(phys)
    assert edit.dtype == np.float32 and edit.shape == phys.shape
    assert np.array_equal(phys, before)
    edit_before = edit.copy()
    back = space.from_edit(edit)
    assert back.dtype == np.float32 and back.shape == phys.shape
    assert np.array_equal(edit, edit_before)
    assert not np.shares_memory(back, edit) and not np.shares_memory(edit, phys)
    with pytest.raises(ValueError):
        space.to_edit(np.zeros((3, space.phys_channels + 1), np.float32))


# --- round trips -------------------------------------------------------------------------


def assert_round_trip(name: str, phys: np.ndarray) -> tuple[float, float]:
    """Check the tolerance; return the max relative error over the typical range
    and the max absolute error below it."""
    space = SPACES[name]
    rtol, atol = tolerance(name)
    back = space.from_edit(space.to_edit(phys)).astype(np.float64)
    a = phys.astype(np.float64)
    err = np.abs(back - a)
    bad = err > rtol * np.abs(a) + atol
    assert not bad.any(), f"{name}: {a[bad][:5]} -> {back[bad][:5]}"
    lo, hi = TYPICAL[family_of(name)]
    typical = (a >= np.float32(lo)) & (a <= hi)
    rel = err[typical] / a[typical]
    return float(rel.max(initial=0.0)), float(err[a < np.float32(lo)].max(initial=0.0))


@pytest.mark.parametrize("name", sorted(SPACES))
def test_round_trip_dense_grid(name, capsys):
    rel, abs_ = assert_round_trip(name, dense_grid(name))
    lo, hi = TYPICAL[family_of(name)]
    with capsys.disabled():
        print(
            f"\n  round trip {name:30s} rel err {rel:.1e} over [{lo:.3g}, {hi:.3g}],"
            f" abs err {abs_:.1e} below",
            end="",
        )


@pytest.mark.parametrize("name", sorted(SPACES))
@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_round_trip_hypothesis(name, data):
    lo, hi = domain(name)
    lo, hi = float(np.float32(lo)), float(np.float32(hi))
    elements = st.floats(lo, hi, width=32, allow_subnormal=False)
    channels = SPACES[name].phys_channels
    phys = data.draw(
        hnp.arrays(np.float32, st.tuples(st.integers(1, 8), st.just(channels)), elements=elements)
    )
    assert_round_trip(name, phys)


@pytest.mark.parametrize("name", ["ggx", "ggx_alpha", "ggx_median"])
def test_ggx_8bit_codes_survive(name):
    space = SPACES[name]
    codes = np.arange(256)
    r = (codes / 255.0).astype(np.float32)[:, None]
    back = space.from_edit(space.to_edit(r))
    assert np.array_equal(np.rint(back[:, 0] * 255.0).astype(int), codes)
    assert np.abs(back - r).max() <= 1.2e-7


# --- monotonicity, scaling, clamping -----------------------------------------------------


@pytest.mark.parametrize("name", sorted(SPACES))
def test_edit_monotone_in_lobe_width(name):
    """Edit values grow with the lobe's width: down with Phong n, up with m and r.

    Strictly over the typical range; over the whole domain only weakly, since
    float32 cannot resolve the edit value's change for tiny exponents.
    """
    space = SPACES[name]
    sign = -1.0 if family_of(name) in ("phong", "ashikhmin_shirley") else 1.0
    lo, hi = TYPICAL[family_of(name)]
    typical = np.unique(np.geomspace(lo, hi, 2001).astype(np.float32))
    for phys, strict in ((typical, True), (dense_grid(name)[:, 0], False)):
        edit = space.to_edit(np.repeat(phys[:, None], space.phys_channels, axis=1))
        step = sign * np.diff(edit, axis=0)
        assert np.all(step > 0) if strict else np.all(step >= 0)
    # and back: from_edit is monotone over the whole edit range (flat where clamped)
    e = np.linspace(space.edit_range.lo - 1.0, space.edit_range.hi + 1.0, 4001, dtype=np.float32)
    back = space.from_edit(np.repeat(e[:, None], space.phys_channels, axis=1))
    assert np.all(sign * np.diff(back.astype(np.float64), axis=0) >= 0)


@pytest.mark.parametrize("name", sorted(SPACES))
def test_scaling_by_one_is_identity(name):
    space = SPACES[name]
    phys = dense_grid(name)[::50]
    edit = space.to_edit(phys)
    assert np.array_equal(space.from_edit(edit * np.float32(1.0)), space.from_edit(edit))
    fit = scaling_fit(space, scales=np.array([1.0]))
    assert fit.errors.max() < 1e-5


ABSURD = np.array([-np.inf, -1e30, -1e3, -1.0, 0.0, 1e-30, 1e-8, 1e3, 1e30, np.inf], np.float32)


@pytest.mark.parametrize("name", sorted(SPACES))
def test_absurd_edit_values_clamp_to_range(name):
    space = SPACES[name]
    lo, hi = DOMAIN[family_of(name)]
    back = space.from_edit(np.repeat(ABSURD[:, None], space.phys_channels, axis=1))
    assert np.all(np.isfinite(back))
    assert np.all((back >= lo) & (back <= hi))
    # absurd physical values map to finite edit values
    edit = space.to_edit(np.repeat(ABSURD[1:-1, None], space.phys_channels, axis=1))
    assert np.all(np.isfinite(edit))


@pytest.mark.parametrize("key", COORDINATE_KEYS["ashikhmin_shirley"])
def test_ashikhmin_shirley_channels_are_independent_phong(key):
    as_space = SPACES[f"ashikhmin_shirley_{key}"]
    ph = SPACES[f"phong_{key}"]
    rng = np.random.default_rng(1)
    nu = rng.uniform(0.0, 1e4, 64).astype(np.float32)
    nv = rng.uniform(0.0, 1e4, 64).astype(np.float32)
    edit = as_space.to_edit(np.stack([nu, nv], axis=-1))
    assert np.array_equal(edit[:, 0], ph.to_edit(nu[:, None])[:, 0])
    assert np.array_equal(edit[:, 1], ph.to_edit(nv[:, None])[:, 0])
    # changing one channel never touches the other, both ways
    edit2 = as_space.to_edit(np.stack([nu, nv[::-1]], axis=-1))
    assert np.array_equal(edit2[:, 0], edit[:, 0])
    edited = edit.copy()
    edited[:, 1] *= np.float32(3.0)
    back = as_space.from_edit(edited)
    assert np.array_equal(back[:, 0], as_space.from_edit(edit)[:, 0])
    assert np.array_equal(back[:, 1], ph.from_edit(edited[:, 1:])[:, 0])


# --- the Fig. 5 table --------------------------------------------------------------------

# MATH.md's figures: (all, fits)
MATH_TABLE = {
    "phong_paper": (0.41, 0.41),
    "phong_small_angle": (0.28, 0.066),
    "phong_median": (0.28, 0.047),
    "beckmann_identity": (0.28, 0.27),
    "beckmann_median": (1.0, 0.15),
    "ggx_alpha": (0.31, 0.29),
    "ggx_median": (1.0, 0.20),
}
TABLE_TOL = 0.02


@pytest.fixture(scope="module")
def fits():
    names = [f"{f}_{k}" for f in ("phong", "beckmann", "ggx") for k in COORDINATE_KEYS[f]]
    return {name: scaling_fit(SPACES[name]) for name in names}


class _UnclampedAlpha(Space):
    """GGX on alpha itself with no ``alpha <= 1`` cap: the space MATH.md's GGX rows measure."""

    phys_channels = edit_channels = 1
    edit_range = EditRange(0.0, 1.0)

    def __init__(self, name, to_edit, from_edit):
        self.name, self._to, self._from = name, to_edit, from_edit

    def to_edit(self, phys):
        return self._to(np.asarray(phys, np.float64)).astype(np.float32)

    def from_edit(self, edit):
        return self._from(np.asarray(edit, np.float64)).astype(np.float32)


GGX_ON_ALPHA = Family("ggx", "alpha", lobes.ggx_cdf, lobes.ggx_cdf_inv, 0.02, 1.0)


def test_fig5_table(fits, capsys):
    lines = [
        "",
        "Fig. 5 check: max |CDF error|, s in [0.25, 4], fits = 95% angle < 60 deg",
        f"{'coordinate':22s} {'all (param, s)':>24s} {'MATH.md':>8s}"
        f" {'fits (param, s)':>24s} {'MATH.md':>8s}",
    ]
    for name, fit in fits.items():
        a, f = fit.worst_all, fit.worst_fits
        ma, mf = MATH_TABLE[name]
        lines.append(
            f"{name:22s} {a.error:8.3f} ({a.param:7.3g},{a.scale:5.3g}) {ma:8.3g}"
            f" {f.error:8.3f} ({f.param:7.3g},{f.scale:5.3g}) {mf:8.3g}"
        )
    ggx_a = fits["ggx_alpha"]
    half = ggx_a.params[:, None] <= 0.5
    unclamped_alpha = scaling_fit(
        _UnclampedAlpha("alpha, no cap", lambda a: a, lambda e: np.maximum(e, 0.0)), GGX_ON_ALPHA
    )
    unclamped_median = scaling_fit(
        _UnclampedAlpha(
            "median, no cap", np.arctan, lambda e: np.tan(np.clip(e, 0.0, np.pi / 2 - 1e-3))
        ),
        GGX_ON_ALPHA,
    )
    u_half = unclamped_alpha.worst(unclamped_alpha.params[:, None] <= 0.5).error
    lines += [
        f"ggx_alpha, alpha <= 0.5: fits {ggx_a.worst(half & ggx_a.fits).error:.3f},"
        f" all {ggx_a.worst(half).error:.3f} (MATH.md 0.12)",
        f"GGX with alpha uncapped: alpha all {unclamped_alpha.worst_all.error:.3f}"
        f" (alpha <= 0.5: {u_half:.3f}), median all {unclamped_median.worst_all.error:.3f}",
    ]
    with capsys.disabled():
        print("\n".join(lines))

    for name, fit in fits.items():
        ma, mf = MATH_TABLE[name]
        assert fit.worst_fits.error == pytest.approx(mf, abs=TABLE_TOL), name
        if name.endswith("_median") and name != "phong_median":
            continue  # "~1 (diverges)": checked below
        assert fit.worst_all.error == pytest.approx(ma, abs=TABLE_TOL), name

    # where MATH.md names the worst case
    assert fits["phong_paper"].worst_all[1:] == pytest.approx((1.0, 0.25))
    assert fits["phong_paper"].worst_fits[1:] == pytest.approx((1.0, 0.25))
    assert fits["phong_small_angle"].worst_all[1:] == pytest.approx((1.0, 4.0))
    assert fits["ggx_alpha"].worst_fits[1:] == pytest.approx((1.0, 0.25))

    # Beckmann median diverges once s * median > 90 deg: the clamp at M_MAX (median
    # 89.3 deg) leaves a lobe on the horizon; the error tends to 1 as the cap nears 90.
    assert fits["beckmann_median"].worst_all.error > 0.9
    # MATH.md's GGX rows are for alpha without the engines' cap alpha <= 1:
    assert unclamped_alpha.worst_all.error == pytest.approx(0.31, abs=TABLE_TOL)
    assert u_half == pytest.approx(0.12, abs=TABLE_TOL)
    assert unclamped_median.worst_all.error > 0.95
    # ...with the cap both GGX coordinates share the same worst case (alpha = 1, s = 4)
    assert fits["ggx_median"].worst_all == fits["ggx_alpha"].worst_all
    assert fits["ggx_alpha"].worst_all[1:] == pytest.approx((1.0, 4.0))
    # and the alpha <= 0.5 fitting lobes stay well inside MATH.md's 0.12
    assert ggx_a.worst(half & ggx_a.fits).error < 0.12


def test_ashikhmin_shirley_fits_like_phong(fits):
    for key in COORDINATE_KEYS["ashikhmin_shirley"]:
        fit = scaling_fit(SPACES[f"ashikhmin_shirley_{key}"])
        assert np.array_equal(fit.errors, fits[f"phong_{key}"].errors)


@pytest.mark.parametrize("family", ["phong", "beckmann", "ggx", "ashikhmin_shirley"])
def test_defaults_are_best_fitting(fits, family):
    measured = "phong" if family == "ashikhmin_shirley" else family
    by_key = {key: fits[f"{measured}_{key}"] for key in COORDINATE_KEYS[measured]}
    best = best_coordinate(by_key, PAPER[measured])
    module = MODULES[family]
    assert module.DEFAULT_COORDINATE == best
    default, explicit = SPACES[family], SPACES[f"{family}_{best}"]
    probe = dense_grid(f"{family}_{best}")[::97]
    assert np.array_equal(default.to_edit(probe), explicit.to_edit(probe))
    # the paper's coordinate stays available by name
    assert f"{family}_{PAPER[measured]}" in SPACES


def test_fit_family_table_matches_math_ranges():
    assert (FAMILIES["phong"].lo, FAMILIES["phong"].hi) == (1.0, 1.0e4)
    for name in ("beckmann", "ggx"):
        assert (FAMILIES[name].lo, FAMILIES[name].hi) == (0.02, 1.0)
