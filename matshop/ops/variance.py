"""Variance kept: the tilt an averaging removes, carried into the lobe's width.

Blurring or downsizing a normal map averages small-scale tilt away, so the
result rendered from afar has a sharper, shinier highlight than the detailed
material seen from the same distance (specular aliasing; Toksvig 2005, LEAN
mapping, Olano and Baker 2010). For a linear averaging ``A`` (rows summing to
one) over the normals' slopes ``s = (-n_x/n_z, -n_y/n_z)`` the covariance the
averaging removes is ``A(s s^T) - A(s) A(s)^T``; adding its trace to the
lobe's total slope variance (``alpha^2`` for GGX and Beckmann; a tabulated
lobe's slopes convolved with a Gaussian of that variance,
:mod:`.sampled_widening`) keeps the far-field look. docs/variance.md has the
derivation and the measurement.

Pure functions over arrays: :func:`lost_slope_covariance` needs only normals
and the averaging; :func:`widen_lobes` rewrites the lobe channels of an edit
array and never narrows a lobe or touches any other channel.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from ..material import Schema
from ..spaces.base import Space
from ..spaces.sampled import SampledDistributionSpace
from .sampled_widening import widen_tabulated
from .spec import OpError

#: An averaging: ``(H, W, C) float32 -> (H', W', C) float32``, linear, weights summing to 1.
Average = Callable[[np.ndarray], np.ndarray]

#: Grazing normals have unbounded slopes; cap ``n_z`` at cos(87 deg) (slope ~19)
#: so one bad texel cannot make a whole footprint rough.
MIN_NZ = 0.05

#: Lobe families widened here, by the ``family`` attribute of their space.
WIDENED_FAMILIES = ("ggx", "beckmann", "phong", "ashikhmin_shirley")


def slopes(normal: np.ndarray) -> np.ndarray:
    """Unit tangent-space normals ``(..., 3)`` -> microfacet slopes ``(..., 2)``, float64.

    ``s = (-n_x / n_z, -n_y / n_z)``: the slope of the facet plane along x and y;
    ``n_z`` is clamped to :data:`MIN_NZ` from below.
    """
    n = np.asarray(normal, dtype=np.float64)
    nz = np.maximum(n[..., 2], MIN_NZ)
    return np.stack([-n[..., 0] / nz, -n[..., 1] / nz], axis=-1)


def _clamp_psd(xx: np.ndarray, xy: np.ndarray, yy: np.ndarray) -> np.ndarray:
    """Symmetric 2x2 ``[[xx, xy], [xy, yy]]`` with negative eigenvalues set to 0, ``(..., 3)``.

    An averaging with negative weights (Lanczos) or rounding can leave a
    slightly indefinite matrix; a variance cannot be negative.
    """
    mean = 0.5 * (xx + yy)
    radius = np.sqrt((0.5 * (xx - yy)) ** 2 + xy * xy)
    big, small = mean + radius, mean - radius
    out = np.stack([xx, xy, yy], axis=-1)
    # one negative eigenvalue: keep big * v v^T, with v v^T = (S - small I) / (big - small)
    one_neg = (small < 0) & (big > 0)
    scale = np.where(one_neg, big / np.where(one_neg, 2.0 * radius, 1.0), 0.0)
    projected = np.stack([xx - small, xy, yy - small], axis=-1) * scale[..., None]
    out = np.where(one_neg[..., None], projected, out)
    return np.where((big <= 0)[..., None], 0.0, out)


def slope_moments(normal: np.ndarray) -> np.ndarray:
    """The five slope moments ``(s_x, s_y, s_x^2, s_x s_y, s_y^2)`` an averaging must
    average, ``(H, W, 5)`` float32.

    The slopes are taken relative to their image median: the covariance does not
    change (the weights sum to one), float32 averaging then loses little to
    cancellation, and a constant tilt gives exactly zero (its mean, summed in
    float64, can differ from it in the last bit; its median cannot).
    """
    s = slopes(normal)
    s = s - np.median(s.reshape(-1, 2), axis=0)
    sx, sy = s[..., 0], s[..., 1]
    moments = np.stack([sx, sy, sx * sx, sx * sy, sy * sy], axis=-1).astype(np.float32)
    return np.ascontiguousarray(moments)


def moments_covariance(averaged: np.ndarray) -> np.ndarray:
    """``A(s s^T) - A(s) A(s)^T`` from averaged :func:`slope_moments`: ``(H, W, 3)``
    ``(xx, xy, yy)``, float64, positive semi-definite per texel."""
    m = np.asarray(averaged, dtype=np.float64)
    mx, my = m[..., 0], m[..., 1]
    return _clamp_psd(m[..., 2] - mx * mx, m[..., 3] - mx * my, m[..., 4] - my * my)


def lost_slope_covariance(normal: np.ndarray, average: Average) -> np.ndarray:
    """Slope covariance ``A(s s^T) - A(s) A(s)^T`` the averaging removes: ``(H', W', 3)``.

    Channels are ``(xx, xy, yy)``, float64, positive semi-definite per texel.
    """
    return moments_covariance(average(slope_moments(normal)))


# --------------------------------------------------------------------------- lobes
# Each takes physical values and the slope variance to add (per axis for the
# anisotropic lobe) and returns widened physical values.


def _ggx(r: np.ndarray, added: np.ndarray) -> np.ndarray:
    # engines store r with alpha = r^2; total slope variance alpha^2 (docs/variance.md)
    alpha = np.clip(r, 0.0, 1.0) ** 2
    return np.sqrt(np.minimum(np.sqrt(alpha * alpha + added), 1.0))


def _beckmann(m: np.ndarray, added: np.ndarray) -> np.ndarray:
    # per-axis slope variance m^2 / 2, so the total is m^2
    m = np.maximum(m, 0.0)
    return np.sqrt(m * m + added)


def _phong(n: np.ndarray, added: np.ndarray) -> np.ndarray:
    # Walter et al. 2007: Phong n matches Beckmann m^2 = 2 / (n + 2)
    return np.maximum(2.0 / (2.0 / (np.maximum(n, 0.0) + 2.0) + added) - 2.0, 0.0)


def _axis_exponent(n: np.ndarray, added_axis: np.ndarray) -> np.ndarray:
    # one axis of Ashikhmin-Shirley: per-axis slope variance 1 / (n + 2)
    return np.maximum(1.0 / (1.0 / (np.maximum(n, 0.0) + 2.0) + added_axis) - 2.0, 0.0)


def _tangent_axes(cov: np.ndarray, tangent: np.ndarray | None) -> np.ndarray:
    """Slope variances ``(..., 2)`` along the tangent and bitangent (x and y without a tangent)."""
    xx, xy, yy = cov[..., 0], cov[..., 1], cov[..., 2]
    if tangent is None:
        return np.stack([xx, yy], axis=-1)
    # the tangent's direction in the texture plane; Sigma rotated into (t, b)
    angle = np.arctan2(tangent[..., 1], tangent[..., 0])
    c, s = np.cos(angle), np.sin(angle)
    uu = c * c * xx + 2 * c * s * xy + s * s * yy
    vv = s * s * xx - 2 * c * s * xy + c * c * yy
    return np.stack([uu, vv], axis=-1)


def _widen_physical(
    space: Space, phys: np.ndarray, cov: np.ndarray, tangent: np.ndarray | None
) -> np.ndarray:
    trace = (cov[..., 0] + cov[..., 2])[..., None]
    family = space.family  # type: ignore[attr-defined]
    if family == "ggx":
        return _ggx(phys, trace)
    if family == "beckmann":
        return _beckmann(phys, trace)
    if family == "phong":
        return _phong(phys, trace)
    return _axis_exponent(phys, _tangent_axes(cov, tangent))


def widen_render_lobe(
    family: str, lobe: np.ndarray, cov: np.ndarray, tangent: np.ndarray | None = None
) -> np.ndarray:
    """The renderer's lobe parameters ``(H, W, 2)`` widened by the slope covariance ``cov``.

    The parameters are :func:`matshop.render.surface.prepare`'s: GGX ``alpha`` (not
    ``r``), Beckmann ``m``, Phong ``n`` (channel 0), Ashikhmin-Shirley ``(nu, nv)``
    along ``tangent`` (x and y without). Never narrower than ``lobe``; the second
    channel of the isotropic families is kept.
    """
    if family not in WIDENED_FAMILIES:
        raise ValueError(f"cannot widen a {family!r} lobe ({', '.join(WIDENED_FAMILIES)})")
    lobe = np.asarray(lobe, dtype=np.float64)
    trace = cov[..., 0] + cov[..., 2]
    out = lobe.copy()
    if family == "ashikhmin_shirley":
        out = np.minimum(_axis_exponent(lobe, _tangent_axes(cov, tangent)), lobe)
    elif family == "phong":
        out[..., 0] = np.minimum(_phong(lobe[..., 0], trace), lobe[..., 0])
    elif family == "beckmann":
        out[..., 0] = np.maximum(_beckmann(lobe[..., 0], trace), lobe[..., 0])
    else:
        alpha = np.clip(lobe[..., 0], 0.0, 1.0)
        out[..., 0] = np.maximum(_ggx(np.sqrt(alpha), trace) ** 2, lobe[..., 0])
    return out


def lobe_parameters(schema: Schema) -> list[str]:
    """Names of the lobe parameters :func:`widen_lobes` rewrites (analytic and sampled)."""
    return [
        param.name
        for param in schema.parameters
        if getattr(param.space, "family", None) in WIDENED_FAMILIES
        or isinstance(param.space, SampledDistributionSpace)
    ]


def _widened_sampled(
    space: SampledDistributionSpace, block: np.ndarray, trace: np.ndarray
) -> np.ndarray:
    """Inverse-CDF edit values of tabulated lobes widened by the slope variance ``trace``.

    The widening is computed on the lobes (:mod:`.sampled_widening`) and added to the
    edit values as the change of their quantiles, ``e + Q(widened) - Q(d)``, so the
    round trip's own error (and whatever legal out-of-range values ``e`` holds) is not
    written back: a vanishing variance changes a vanishing amount.
    """
    lobe = space.from_edit(block)
    return block + (space.to_edit(widen_tabulated(lobe, trace)) - space.to_edit(lobe))


def widen_lobes(
    edit: np.ndarray,
    schema: Schema,
    cov: np.ndarray,
    *,
    tangent: np.ndarray | None = None,
    mask: np.ndarray | None = None,
    op: str = "keep variance",
) -> np.ndarray:
    """``edit`` with every lobe parameter widened by the slope covariance ``cov`` (``(H, W, 3)``).

    Parameters
    ----------
    edit : (H, W, C) float32 edit array laid out by ``schema``; not modified.
    cov : (H, W, 3) lost slope covariance ``(xx, xy, yy)`` (:func:`lost_slope_covariance`).
    tangent : (H, W, 3) tangent-space tangents, or None; Ashikhmin-Shirley's
        ``nu`` / ``nv`` take the variance along them (x and y without).
    mask : (H, W) in [0, 1]: the widening is blended in by it, as an op's mask blends.

    The lobe never narrows: every edit coordinate grows with the lobe's width,
    so the result is the larger of the old and the widened edit value, and
    texels with no lost variance keep their exact bits. Other channels are
    copied unchanged.
    """
    names = lobe_parameters(schema)
    if not names:
        raise OpError(
            f"{op}: the material has no lobe parameter to widen (roughness, "
            "beckmann_roughness, phong_exponent, anisotropic_exponents or distribution)"
        )
    out = edit.copy()
    trace = cov[..., 0] + cov[..., 2]
    lost = trace > 0
    for name in names:
        space = schema[name].space
        block = np.ascontiguousarray(edit[..., schema.edit_slices[name]])
        if isinstance(space, SampledDistributionSpace):
            widened = block.copy()  # only the texels that lost tilt pay for the widening
            widened[lost] = _widened_sampled(space, block[lost], trace[lost])
        else:
            widened = space.to_edit(_widen_physical(space, space.from_edit(block), cov, tangent))
        widened = np.maximum(widened.astype(np.float32), block)
        if mask is not None:
            widened = block + mask[..., None] * (widened - block)
        out[..., schema.edit_slices[name]] = np.where(lost[..., None], widened, block)
    return out


def normal_moments(edit: np.ndarray, schema: Schema) -> np.ndarray:
    """:func:`slope_moments` of the normals of an edit array laid out by ``schema``."""
    space = schema["normal"].space
    frame = space.from_edit(np.ascontiguousarray(edit[..., schema.edit_slices["normal"]]))
    return slope_moments(frame[..., :3])


def widen_smoothed(
    after: np.ndarray,
    schema: Schema,
    cov: np.ndarray,
    *,
    mask: np.ndarray | None = None,
    op: str = "keep variance",
) -> np.ndarray:
    """:func:`widen_lobes` of an op's result, the anisotropic axes along the result's own
    tangents (when its normal space carries a frame)."""
    frame = schema["normal"].space.from_edit(
        np.ascontiguousarray(after[..., schema.edit_slices["normal"]])
    )
    tangent = frame[..., 3:6] if frame.shape[-1] >= 6 else None
    return widen_lobes(after, schema, cov, tangent=tangent, mask=mask, op=op)


def smooths_normals(schema: Schema | None, groups: Iterable[str]) -> bool:
    """Whether the op's selected channel groups (``normal``, ``normal.x``...) include the
    normals of ``schema``."""
    return schema is not None and "normal" in schema and "normal" in {
        g.split(".")[0] for g in groups
    }
