"""SubEdit subsurface scattering profiles ``p(r)``.

Physical: ``(..., N)`` float32, ``N = 32`` by default, ``p`` at the bin centres
``r_k = (k + 1/2) r_max / N`` and read as constant over each bin
``[k, k + 1] r_max / N``. ``r`` is in the length unit of the texture set (the
profile's metadata states it; millimetres by convention), so ``p`` is in
1/unit^2 and ``r_max`` (constructor parameter, default 1.0) is in that unit.

Edit (MATH.md "SubEdit subsurface profiles"), ``N + 1`` channels:

- channel 0: albedo ``A = integral_0^r_max p(r) r dr``, linear like a color;
- channels 1..N: the normalised profile's inverse CDF ``C^-1(y)`` (radii) at
  fixed levels ``y``, the same level grid and kernels as the sampled lobes
  (``_inverse_cdf.py``): cosine-spaced by default.

The PCHIP runs between ``C`` and ``r`` (``interp="r"``, default; ``"r2"`` uses
``r^2``, exact for bin-wise constant profiles but worse on the ``1/r`` peak of
diffusion profiles). Back: the quantiles become a monotone ``C(r)`` (PCHIP),
``pn`` is its exact bin average ``(C(b) - C(a)) / ((b^2 - a^2) / 2)`` (no
division by ``r`` at a point), ``p = max(A, 0) * pn``. Scaling the radii by
``s > 1`` spreads light ``s`` times further with the albedo unchanged (more
translucent).
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ._inverse_cdf import YGrid, pdf_to_quantiles, quantiles_to_pdf
from ._inverse_cdf import y_grid as _y_grid
from .base import EditRange, Space, as_channels

DEFAULT_SAMPLES = 32
#: PCHIP between C and r (default: diffusion profiles peak like 1/r at the origin,
#: so C ~ r there) or C and r^2 (better for profiles finite at r = 0)
Interp = Literal["r", "r2"]
_INTERP_COORD = {"r2": "square", "r": "x"}
_CHUNK = 1 << 15


def radius_edges(n: int = DEFAULT_SAMPLES, r_max: float = 1.0) -> np.ndarray:
    """The ``n + 1`` bin edges ``k r_max / n`` (float64)."""
    return np.arange(n + 1, dtype=np.float64) * (r_max / n)


def radius_centres(n: int = DEFAULT_SAMPLES, r_max: float = 1.0) -> np.ndarray:
    """The ``n`` bin centres ``(k + 1/2) r_max / n`` where ``p`` is sampled (float64)."""
    return (np.arange(n, dtype=np.float64) + 0.5) * (r_max / n)


def radius_measure(n: int = DEFAULT_SAMPLES, r_max: float = 1.0) -> np.ndarray:
    """``integral_a^b r dr = (b^2 - a^2) / 2`` per bin: albedo = ``sum(p * measure)``."""
    return 0.5 * np.diff(radius_edges(n, r_max) ** 2)


# --------------------------------------------------------------------------- generators


def burley_cdf(r: np.ndarray, d: np.ndarray | float) -> np.ndarray:
    """CDF of Burley's normalised diffusion profile in the ``r dr`` measure.

    ``pn(r) = (exp(-r/d) + exp(-r/(3d))) / (4 d r)`` (Christensen & Burley 2015,
    a sum-of-exponentials stand-in for the dipole; ``integral pn r dr = 1``), so
    ``C(r) = 1 - exp(-r/d)/4 - 3 exp(-r/(3d))/4`` and the mean radius is ``2.5 d``.
    """
    r = np.asarray(r, dtype=np.float64)
    d = np.asarray(d, dtype=np.float64)
    return 1.0 - 0.25 * np.exp(-r / d) - 0.75 * np.exp(-r / (3.0 * d))


def exponential_cdf(r: np.ndarray, length: np.ndarray | float) -> np.ndarray:
    """CDF of the single-exponential profile ``pn(r) = exp(-r/l) / l^2`` (``r dr`` measure).

    ``C(r) = 1 - (1 + r/l) exp(-r/l)``; the mean radius is ``2 l``. Its light tail
    suits tests that scale radii (little mass is pushed past ``r_max``).
    """
    x = np.asarray(r, dtype=np.float64) / np.asarray(length, dtype=np.float64)
    return 1.0 - (1.0 + x) * np.exp(-x)


def _tabulate(albedo, scale, cdf, n: int, r_max: float) -> np.ndarray:
    albedo, scale = np.broadcast_arrays(
        np.asarray(albedo, dtype=np.float64), np.asarray(scale, dtype=np.float64)
    )
    flat_a, flat_s = albedo.reshape(-1), scale.reshape(-1)
    edges = radius_edges(n, r_max)
    measure = radius_measure(n, r_max)
    out = np.empty((flat_a.size, n), dtype=np.float32)
    for start in range(0, flat_a.size, _CHUNK):
        c = cdf(edges[None, :], flat_s[start : start + _CHUNK, None])
        mass = np.diff(c, axis=-1) / c[:, -1:]
        out[start : start + _CHUNK] = flat_a[start : start + _CHUNK, None] * mass / measure
    return out.reshape(*albedo.shape, n)


def profile_burley(
    albedo: np.ndarray | float,
    d: np.ndarray | float,
    *,
    n: int = DEFAULT_SAMPLES,
    r_max: float = 1.0,
) -> np.ndarray:
    """Tabulate ``p = albedo * pn`` (Burley profile of scale ``d``) as ``(..., n)`` float32.

    ``albedo`` and ``d`` broadcast. Each bin holds the exact bin average from
    :func:`burley_cdf`, renormalised over ``[0, r_max]`` so the tabulated albedo
    is exactly ``albedo`` (the tail beyond ``r_max`` is folded back in). Bins
    must resolve the profile: with ``d`` below ~one bin width the ``1/r`` peak
    sits in the first bin and the tabulated mean radius is too large.
    """
    return _tabulate(albedo, d, burley_cdf, n, r_max)


def profile_exponential(
    albedo: np.ndarray | float,
    length: np.ndarray | float,
    *,
    n: int = DEFAULT_SAMPLES,
    r_max: float = 1.0,
) -> np.ndarray:
    """Tabulate ``p = albedo * exp(-r/l) / l^2`` as ``(..., n)`` float32 (bin averages)."""
    return _tabulate(albedo, length, exponential_cdf, n, r_max)


def profile_albedo(p: np.ndarray, r_max: float = 1.0) -> np.ndarray:
    """``A = sum(p * (b^2 - a^2)/2)`` per profile (float64, negatives count)."""
    p = np.asarray(p, dtype=np.float64)
    return np.sum(p * radius_measure(p.shape[-1], r_max), axis=-1)


def mean_radius(p: np.ndarray, r_max: float = 1.0) -> np.ndarray:
    """Mean scattering distance ``integral r pn r dr``, exact for piecewise-constant ``p``.

    Inside a bin the conditional mean of ``r`` under ``r dr`` is
    ``(2/3) (b^3 - a^3) / (b^2 - a^2)``. Independent of the PCHIP machinery.
    """
    p = np.clip(np.asarray(p, dtype=np.float64), 0.0, None)
    n = p.shape[-1]
    e = radius_edges(n, r_max)
    mass = p * radius_measure(n, r_max)
    r_bin = (2.0 / 3.0) * np.diff(e**3) / np.diff(e**2)
    return np.sum(mass * r_bin, axis=-1) / np.sum(mass, axis=-1)


# --------------------------------------------------------------------------- space


class SubsurfaceProfileSpace(Space):
    """Profile ``p(r)`` <-> (albedo, inverse CDF of ``p / albedo`` at fixed levels).

    Attributes
    ----------
    albedo_channel : int
        Edit channel holding the albedo (0); linear, range [0, 1].
    profile_channels : slice
        Edit channels holding the radii ``C^-1(y)`` (1..N); range [0, r_max].
    y, dy : (N,) float64
        Quantile level and quadrature weight (sums to 1) of each profile channel.
    """

    curve_mode = "vector"
    albedo_channel = 0

    def __init__(
        self,
        n: int = DEFAULT_SAMPLES,
        *,
        r_max: float = 1.0,
        y_grid: YGrid = "cosine",
        interp: Interp = "r",
        name: str = "subsurface",
    ) -> None:
        if interp not in _INTERP_COORD:
            raise ValueError(f"unknown interp {interp!r} (use 'r' or 'r2')")
        self.interp = interp
        self._coord = _INTERP_COORD[interp]
        if not r_max > 0:
            raise ValueError(f"r_max must be positive, got {r_max}")
        self.name = name
        self.r_max = float(r_max)
        self.y_grid = y_grid
        self.y, self.dy = _y_grid(n, y_grid)
        self.description = (
            f"subsurface profile p(r), {n} bins up to r_max={r_max:g} <-> "
            f"albedo + inverse CDF at {n} {y_grid} levels"
        )
        self.phys_channels = n
        self.edit_channels = n + 1
        self.profile_channels = slice(1, n + 1)
        self.edit_range = EditRange(0.0, self.r_max)
        self.edges = radius_edges(n, self.r_max)
        self.measure = radius_measure(n, self.r_max)

    def edit_groups(self) -> list[tuple[str, slice, str, EditRange, np.ndarray]]:
        """Albedo is a linear scalar; the inverse CDF is one vector with quadrature ``dy``."""
        return [
            ("albedo", slice(0, 1), "channels", EditRange(0.0, 1.0), np.ones(1)),
            ("profile", self.profile_channels, "vector", self.edit_range, self.dy),
        ]

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        p = as_channels(phys, self.phys_channels, self.name)
        rows = np.ascontiguousarray(p).reshape(-1, self.phys_channels)
        out = np.empty((rows.shape[0], self.edit_channels), dtype=np.float32)
        _, total = pdf_to_quantiles(
            rows,
            edges=self.edges,
            weights=self.measure,
            y=self.y,
            coord=self._coord,
            out=out[:, 1:],
        )
        out[:, 0] = total
        return out.reshape(*p.shape[:-1], self.edit_channels)

    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        e = as_channels(edit, self.edit_channels, self.name)
        rows = np.ascontiguousarray(e).reshape(-1, self.edit_channels)
        p = quantiles_to_pdf(
            rows[:, 1:], edges=self.edges, weights=self.measure, y=self.y, coord=self._coord
        )
        # a non-finite albedo carries no light (keeps the output finite)
        albedo = np.nan_to_num(rows[:, 0], nan=0.0, posinf=0.0)
        p *= np.clip(albedo, 0.0, None)[:, None]
        return p.reshape(*e.shape[:-1], self.phys_channels)


SPACES: dict[str, Space] = {"subsurface": SubsurfaceProfileSpace()}
