"""How well an analytic editing space turns edit scaling into lobe scaling.

The paper's Fig. 5 check (MATH.md "Analytic distributions"): scaling an edit
value by ``s`` should widen the lobe's angles by ``s``, i.e. turn the CDF
``c(theta)`` into ``c_s(theta) = c(theta / s)``. For ``s > 1`` that pushes
mass past 90 degrees, so the exact scaled lobe is cut at the horizon and
renormalised: ``c_s(theta) = c(theta / s) / c(pi / (2 s))``. The space
predicts the parameter ``p' = from_edit(s * to_edit(p))``; the error of one
``(p, s)`` is ``max_theta |c_s(theta) - c(theta; p')|``.

The maximum over ``theta`` is taken on a grid made of ``samples`` quantiles of
each of the two lobes plus ``samples`` uniform angles: between neighbouring
grid angles each CDF rises by at most ``1 / (samples - 1)``, so the reported
error is below the true supremum by at most that much (0.004 by default).
Everything is evaluated in float64 from the closed forms in
:mod:`matshop.spaces.lobes`, except the space itself, which runs as it does
in the editor (float32).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from . import lobes
from .base import Space

FITS_ANGLE = np.deg2rad(60.0)
"""A scaled lobe "fits the hemisphere" when its 95% angle is below this."""


@dataclass(frozen=True)
class Family:
    """An analytic lobe family: its CDF and how its parameter is stored.

    ``to_phys`` maps the lobe parameter (``n``, ``m``, ``alpha``) to what the
    space's ``to_edit`` takes (GGX: perceptual ``r = sqrt(alpha)``), and
    ``from_phys`` maps back.
    """

    name: str
    parameter: str
    cdf: Callable[[np.ndarray, np.ndarray], np.ndarray]
    cdf_inv: Callable[[np.ndarray, np.ndarray], np.ndarray]
    lo: float
    hi: float
    to_phys: Callable[[np.ndarray], np.ndarray] = np.asarray
    from_phys: Callable[[np.ndarray], np.ndarray] = np.asarray


FAMILIES: dict[str, Family] = {
    "phong": Family("phong", "n", lobes.phong_cdf, lobes.phong_cdf_inv, 1.0, 1.0e4),
    "beckmann": Family("beckmann", "m", lobes.beckmann_cdf, lobes.beckmann_cdf_inv, 0.02, 1.0),
    "ggx": Family("ggx", "alpha", lobes.ggx_cdf, lobes.ggx_cdf_inv, 0.02, 1.0, np.sqrt, np.square),
}
FAMILIES["ashikhmin_shirley"] = FAMILIES["phong"]

DEFAULT_SCALES = np.geomspace(0.25, 4.0, 33)
"""``s`` in [0.25, 4], log-spaced, eight steps per octave (includes 1)."""


class Worst(NamedTuple):
    """The largest error of a set of cases and where it occurs."""

    error: float
    param: float
    scale: float


@dataclass(frozen=True)
class ScalingFit:
    """Per-case CDF errors of one space: ``errors[i, j]`` for ``params[i]``, ``scales[j]``."""

    space: str
    family: str
    params: np.ndarray
    scales: np.ndarray
    errors: np.ndarray
    #: 95% angle of the exact scaled (renormalised) lobe, radians, per case; taking
    #: ``s * c^-1(0.95)`` without renormalising selects the same worst cases here
    angle95: np.ndarray = field(repr=False)

    @property
    def fits(self) -> np.ndarray:
        """Cases whose exact scaled lobe still fits the hemisphere."""
        return self.angle95 < FITS_ANGLE

    def worst(self, mask: np.ndarray | None = None) -> Worst:
        """Largest error over the cases in ``mask`` (all cases by default)."""
        errors = self.errors if mask is None else np.where(mask, self.errors, -np.inf)
        i, j = np.unravel_index(np.argmax(errors), errors.shape)
        return Worst(float(errors[i, j]), float(self.params[i]), float(self.scales[j]))

    @property
    def worst_all(self) -> Worst:
        return self.worst()

    @property
    def worst_fits(self) -> Worst:
        return self.worst(self.fits)


def scaling_fit(
    space: Space,
    family: str | Family | None = None,
    *,
    params: np.ndarray | None = None,
    scales: np.ndarray | None = None,
    samples: int = 257,
) -> ScalingFit:
    """Measure how closely ``space`` turns edit scaling into lobe-angle scaling.

    Parameters
    ----------
    space : Space
        The editing space; a multi-channel space (Ashikhmin-Shirley) gets the
        same parameter in every channel and is charged its worst channel.
    family : str or Family, optional
        Key of :data:`FAMILIES` or a :class:`Family`; by default the space's
        own ``family`` attribute.
    params : (P,) ndarray, optional
        Lobe parameters; default 41 log-spaced over the family's range
        (Phong ``n`` in [1, 1e4], Beckmann ``m`` and GGX ``alpha`` in [0.02, 1]).
    scales : (S,) ndarray, optional
        Edit scale factors; default :data:`DEFAULT_SCALES`.
    samples : int
        Quantiles per lobe in the angle grid (see the module docstring).

    Returns
    -------
    ScalingFit
        Per-case errors with the worst cases overall and over fitting lobes.
    """
    if family is None:
        family = getattr(space, "family", None)
        if family is None:
            raise ValueError(f"{space.name}: no family attribute; pass family=")
    fam = FAMILIES[family] if isinstance(family, str) else family
    p = np.geomspace(fam.lo, fam.hi, 41) if params is None else np.asarray(params, np.float64)
    s = DEFAULT_SCALES if scales is None else np.asarray(scales, np.float64)
    channels = space.phys_channels

    # predicted parameters, shape (P, S, C), through the space in float32
    phys = np.repeat(np.asarray(fam.to_phys(p), np.float32)[:, None, None], channels, axis=-1)
    edit = space.to_edit(phys)
    back = space.from_edit(edit * s.astype(np.float32)[None, :, None])
    # floor at 1e-9: a zero GGX alpha makes its CDF 0/0 at theta = 0
    predicted = np.maximum(np.asarray(fam.from_phys(back.astype(np.float64))), 1e-9)

    # the exact scaled lobe: c(theta / s) / norm, shape (P, S, 1, 1) operands
    pe = p[:, None, None, None]
    se = s[None, :, None, None]
    norm = np.where(se > 1.0, fam.cdf(0.5 * np.pi / se, pe), 1.0)
    y = np.linspace(0.0, 1.0, samples)
    half_pi = 0.5 * np.pi
    with np.errstate(divide="ignore"):
        exact_q = se * fam.cdf_inv(y * norm, pe)
        predicted_q = fam.cdf_inv(y, predicted[..., None])
    uniform = np.broadcast_to(y * half_pi, exact_q.shape)
    theta = np.clip(
        np.concatenate(np.broadcast_arrays(exact_q, predicted_q, uniform), axis=-1), 0.0, half_pi
    )

    # theta / s is clipped at the horizon: beyond it the unscaled lobe is complete
    exact = np.minimum(fam.cdf(np.minimum(theta / se, half_pi), pe) / norm, 1.0)
    errors = np.abs(exact - fam.cdf(theta, predicted[..., None])).max(axis=(-1, -2))
    angle95 = np.clip(se * fam.cdf_inv(0.95 * norm, pe), 0.0, half_pi)[..., 0, 0]
    return ScalingFit(space.name, fam.name, p, s, errors, angle95)


RULE_TOLERANCE = 0.005
"""Errors closer than this are "not worse": the grid's resolution, ``1/256``, rounded up."""


def best_coordinate(fits: dict[str, ScalingFit], paper: str) -> str:
    """The default-coordinate rule of the analytic spaces.

    Among the coordinates in ``fits`` (key -> measurement), keep those whose
    worst error over all lobes is not worse than the ``paper`` coordinate's
    (within :data:`RULE_TOLERANCE`), and pick the one with the lowest worst
    error over the lobes that fit the hemisphere.
    """
    ceiling = fits[paper].worst_all.error + RULE_TOLERANCE
    eligible = [key for key, fit in fits.items() if fit.worst_all.error <= ceiling]
    return min(eligible, key=lambda key: fits[key].worst_fits.error)
