"""Local shading frames: normal maps, normal + tangent frames, bump/height maps.

Physical representation (what the material holds in memory)
    A normal is a unit tangent-space vector ``n = (x, y, z)`` in the OpenGL
    convention (+X right, +Y up, +Z out of the surface), float32 in [-1, 1],
    shape ``(..., 3)``. A normal + tangent frame is ``(..., 6) = (n, t)``.
    File encodings (``rgb = (n + 1) / 2``, green flipped for DirectX) are
    converted by :func:`decode_normal_map` / :func:`encode_normal_map`.

Edit representation (MATH.md, "Local frames")
    The rotation ``R`` taking the geometric frame ``(x, y, z)`` to the local
    frame, as a unit quaternion ``q = (w, x, y, z)`` with ``w >= 0``, stored as
    its logarithm ``q~ = ln q = v/|v| * acos(w)`` (Grassia 1998). ``|q~|`` is
    half the rotation angle, so ``|q~| <= pi/2``. Back: ``q = exp(q~)``,
    ``n = R(q) z``, ``t = R(q) x``; every edit 3-vector maps to a rotation, so
    any linear combination of edit values gives unit normals and orthonormal
    frames. Scaling ``q~`` by ``s`` scales the rotation angle by ``s``;
    ``w * q~`` is exactly ``slerp(identity, q, w)``.

Quaternions in this module are scalar-first ``(w, x, y, z)``, shape ``(..., 4)``.
The numpy helpers compute in float32 with formulas that stay accurate near the
identity (``atan2`` instead of ``acos``, a series for ``sin(x)/x``) and near a
half turn (Shepperd's method picks the best-conditioned component). The two
spaces run the same formulas as fused numba kernels (``_kernels.py``): one
pass per direction, float64 inside, writing straight into strided outputs;
``tests/test_kernels.py`` holds them to the numpy helpers.

Height maps
    :func:`height_to_normal` treats the height as a displacement measured in
    texel widths (times ``strength``); ``u`` runs along image columns (to the
    right) and ``v`` runs *up* the image, i.e. against the row index, so a
    surface that rises towards the top of the image has a normal leaning down
    (``n_y < 0``) in the OpenGL convention.
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidValue
from ._kernels import (
    FRAME_FROM_EDIT,
    FRAME_TO_EDIT,
    NORMAL_FROM_EDIT,
    NORMAL_TO_EDIT,
    Step,
    decode_normals,
    encode_normals,
    normalize_or_z,
)
from .base import EditRange, FusedSpace, Space, as_channels

# the convention guess lives in its own module; re-exported here, where the loader imports it
from .normal_convention import CONFIDENT_GUESS as CONFIDENT_GUESS
from .normal_convention import Convention
from .normal_convention import guess_normal_convention as guess_normal_convention

_CONVENTIONS = ("opengl", "directx")

#: vectors shorter than this are treated as zero length (decode: flat normal)
_TINY_LENGTH = np.float32(1e-12)
#: below this |x| the series 1 - x^2/6 is exact in float32 for sin(x)/x
_SINC_SERIES = np.float32(1e-3)
_F32 = np.float32


# ---------------------------------------------------------------------------
# small vector helpers


def _check_convention(convention: str) -> None:
    if convention not in _CONVENTIONS:
        raise InvalidValue(
            f"normal map convention must be 'opengl' or 'directx', got {convention!r}"
        )


def _normalize_or_z(v: np.ndarray) -> np.ndarray:
    """Unit vectors along ``v`` (..., 3); zero-length (or NaN) vectors become ``+z``.

    One fused pass (a 2K map is read and written when every normal map is
    decoded and encoded); numpy's float32 arithmetic, so the same bits.
    """
    flat = np.ascontiguousarray(v, dtype=np.float32).reshape(-1, 3)
    out = np.empty_like(flat)
    normalize_or_z(flat, _TINY_LENGTH, out)
    return out.reshape(np.shape(v))


def _sinc(x: np.ndarray) -> np.ndarray:
    """``sin(x) / x`` for ``x >= 0``, exact near 0."""
    small = x < _SINC_SERIES
    safe = np.where(small, _F32(1.0), x)
    return np.where(small, _F32(1.0) - x * x / _F32(6.0), np.sin(safe) / safe).astype(np.float32)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.cross(a, b).astype(np.float32, copy=False)


# ---------------------------------------------------------------------------
# quaternions (scalar first)


def quat_exp(log_q: np.ndarray) -> np.ndarray:
    """``exp`` of a pure quaternion ``q~`` (..., 3) -> unit quaternion ``(w, x, y, z)``.

    ``exp(q~) = (cos|q~|, sin|q~| q~/|q~|)``; defined for every finite 3-vector.
    """
    e = np.asarray(log_q, dtype=np.float32)
    phi = np.sqrt(np.sum(e * e, axis=-1, keepdims=True))
    q = np.concatenate([np.cos(phi), _sinc(phi) * e], axis=-1)
    # |q| = 1 up to rounding; renormalise so rotations stay exactly orthonormal
    return (q / np.sqrt(np.sum(q * q, axis=-1, keepdims=True))).astype(np.float32, copy=False)


def quat_log(q: np.ndarray) -> np.ndarray:
    """``ln`` of a unit quaternion ``(w, x, y, z)`` with ``w >= 0`` -> 3-vector.

    ``ln q = v/|v| * acos(w)``, computed as ``v * atan2(|v|, w) / |v|`` (zero for
    the identity). The sign of ``q`` is fixed to ``w >= 0`` first, so the result
    is the shortest-path logarithm with ``|ln q| <= pi/2``.
    """
    q = np.asarray(q, dtype=np.float32)
    q = np.where(q[..., :1] < 0, -q, q)
    w = q[..., :1]
    v = q[..., 1:]
    s = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    ok = s > _F32(1e-30)
    ratio = np.where(ok, np.arctan2(s, w) / np.where(ok, s, _F32(1.0)), _F32(1.0))
    return (v * ratio).astype(np.float32, copy=False)


def quat_rotate(q: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """Rotate ``vec`` (..., 3) by the unit quaternion ``q`` (..., 4): ``q vec q*``."""
    q = np.asarray(q, dtype=np.float32)
    vec = np.asarray(vec, dtype=np.float32)
    w = q[..., :1]
    u = q[..., 1:]
    # v' = v + 2 w (u x v) + 2 u x (u x v)
    uv = np.cross(u, vec)
    return (vec + _F32(2.0) * (w * uv + np.cross(u, uv))).astype(np.float32, copy=False)


def _quat_rotate_z(q: np.ndarray) -> np.ndarray:
    """``R(q) z``: the third column of the rotation matrix."""
    w, x, y, z = (q[..., i] for i in range(4))
    two = _F32(2.0)
    return np.stack(
        [two * (x * z + w * y), two * (y * z - w * x), _F32(1.0) - two * (x * x + y * y)], axis=-1
    )


def _quat_rotate_x(q: np.ndarray) -> np.ndarray:
    """``R(q) x``: the first column of the rotation matrix."""
    w, x, y, z = (q[..., i] for i in range(4))
    two = _F32(2.0)
    return np.stack(
        [_F32(1.0) - two * (y * y + z * z), two * (x * y + w * z), two * (x * z - w * y)], axis=-1
    )


def quat_from_matrix(rot: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) -> unit quaternions ``(w, x, y, z)``, ``w >= 0``.

    Shepperd's method (1978): of ``4w^2 = 1 + tr``, ``4x^2 = 1 + R00 - R11 - R22``,
    ... the largest is taken with a square root and the other components come
    from off-diagonal sums/differences divided by it, which is well conditioned
    for every rotation including half turns. Vectorised with one mask per case.
    """
    m = np.asarray(rot, dtype=np.float32)
    if m.shape[-2:] != (3, 3):
        raise ValueError(f"quat_from_matrix: expected (..., 3, 3), got shape {m.shape}")
    r00, r01, r02 = m[..., 0, 0], m[..., 0, 1], m[..., 0, 2]
    r10, r11, r12 = m[..., 1, 0], m[..., 1, 1], m[..., 1, 2]
    r20, r21, r22 = m[..., 2, 0], m[..., 2, 1], m[..., 2, 2]
    one = _F32(1.0)
    four_sq = np.stack(
        [
            one + r00 + r11 + r22,
            one + r00 - r11 - r22,
            one - r00 + r11 - r22,
            one - r00 - r11 + r22,
        ],
        axis=-1,
    )
    case = np.argmax(four_sq, axis=-1)
    big = _F32(0.5) * np.sqrt(np.maximum(np.max(four_sq, axis=-1), _F32(0.0)))
    inv = _F32(0.25) / np.maximum(big, _F32(1e-30))  # big >= 1/2 for a rotation matrix
    q = np.empty(m.shape[:-2] + (4,), dtype=np.float32)
    sums = {
        # (w, x, y, z) as functions of the pivot, case by case
        0: (big, (r21 - r12) * inv, (r02 - r20) * inv, (r10 - r01) * inv),
        1: ((r21 - r12) * inv, big, (r01 + r10) * inv, (r02 + r20) * inv),
        2: ((r02 - r20) * inv, (r01 + r10) * inv, big, (r12 + r21) * inv),
        3: ((r10 - r01) * inv, (r02 + r20) * inv, (r12 + r21) * inv, big),
    }
    for k, comps in sums.items():
        mask = case == k
        for i, c in enumerate(comps):
            q[..., i] = np.where(mask, c, q[..., i]) if k else c
    q = np.where(q[..., :1] < 0, -q, q)
    return (q / np.sqrt(np.sum(q * q, axis=-1, keepdims=True))).astype(np.float32, copy=False)


def _normal_log(n: np.ndarray) -> np.ndarray:
    """``ln q`` of the smallest rotation taking ``z`` to the unit normals ``n``.

    Axis ``z x n / |z x n| = (-n_y, n_x, 0) / s``, ``s = |(n_x, n_y)| = sin(theta)``,
    half angle ``theta/2 = atan2(s, n_z)/2``; ``n = -z`` uses the ``x`` axis.
    """
    nx, ny, nz = n[..., 0], n[..., 1], n[..., 2]
    s = np.hypot(nx, ny)
    half = _F32(0.5) * np.arctan2(s, nz)
    ok = s > _F32(1e-30)
    ratio = np.where(ok, half / np.where(ok, s, _F32(1.0)), _F32(0.5))
    out = np.stack([-ny * ratio, nx * ratio, np.zeros_like(nx)], axis=-1)
    flipped = ~ok & (nz < 0)  # exactly -z: half turn about x
    out[..., 0] = np.where(flipped, _F32(np.pi / 2), out[..., 0])
    return out.astype(np.float32, copy=False)


# ---------------------------------------------------------------------------
# spaces


class NormalFrameSpace(FusedSpace):
    """Unit normal (..., 3) <-> log of the smallest rotation taking ``z`` to it (..., 3).

    Edit values from this direction have a zero ``z`` component; ``from_edit``
    accepts any 3-vector (a ``z`` component twists about the normal, which a
    normal alone does not see) and always returns a unit normal. Zero-length,
    infinite or NaN values on either side stand for the flat normal ``+z``.

    Both directions are one fused numba pass (``_kernels.py``) computing in
    float64; :func:`_normal_log` / :func:`quat_exp` + :func:`_quat_rotate_z`
    are the numpy reference the tests compare it with.
    """

    name = "normal"
    description = "normal map: log quaternion of the smallest rotation z -> n (Grassia 1998)"
    phys_channels = 3
    edit_channels = 3
    # |log q| is half the rotation angle, and q_s >= 0 keeps it within pi/2
    edit_range = EditRange(0.0, float(np.pi / 2))
    curve_mode = "vector"

    def to_edit_step(self) -> Step:
        return Step(True, NORMAL_TO_EDIT)

    def from_edit_step(self) -> Step:
        return Step(True, NORMAL_FROM_EDIT)


class NormalTangentFrameSpace(FusedSpace):
    """Normal + tangent (..., 6) = (n, t) <-> log of the rotation to ``(t, n x t, n)`` (..., 3).

    ``n`` is normalised, ``t`` is Gram-Schmidt orthonormalised against ``n``;
    when ``t`` is (nearly) parallel to ``n`` or zero it falls back to the
    tangent of the smallest-rotation frame of ``n``. ``from_edit`` returns the
    flat frame ``(z, x)`` for non-finite edit values.

    Both directions are one fused numba pass (``_kernels.py``);
    :meth:`_reference_to_edit` is the numpy reference the tests compare it with.
    """

    name = "normal_tangent"
    description = "normal + tangent frame: log quaternion of the rotation (x,y,z) -> (t, n x t, n)"
    phys_channels = 6
    edit_channels = 3
    # |log q| is half the rotation angle, and q_s >= 0 keeps it within pi/2
    edit_range = EditRange(0.0, float(np.pi / 2))
    curve_mode = "vector"

    def to_edit_step(self) -> Step:
        return Step(True, FRAME_TO_EDIT)

    def from_edit_step(self) -> Step:
        return Step(True, FRAME_FROM_EDIT)

    def _reference_to_edit(self, phys: np.ndarray) -> np.ndarray:
        """The numpy (float32) formulation of ``to_edit``, kept as a test reference."""
        frame = as_channels(phys, self.phys_channels, self.name)
        n = _normalize_or_z(frame[..., :3])
        t = frame[..., 3:]
        t_len = np.sqrt(np.sum(t * t, axis=-1, keepdims=True))
        t_perp = t - np.sum(t * n, axis=-1, keepdims=True) * n
        perp_len = np.sqrt(np.sum(t_perp * t_perp, axis=-1, keepdims=True))
        # degenerate when t is zero or within ~1e-3 rad of +-n
        ok = perp_len > np.maximum(_F32(1e-3) * t_len, _TINY_LENGTH)
        fallback = _quat_rotate_x(quat_exp(_normal_log(n)))
        t = np.where(ok, t_perp / np.where(ok, perp_len, _F32(1.0)), fallback)
        t = t - np.sum(t * n, axis=-1, keepdims=True) * n  # second pass: float32 cleanup
        t = t / np.sqrt(np.sum(t * t, axis=-1, keepdims=True))
        b = _cross(n, t)
        rot = np.stack([t, b, n], axis=-1)  # columns: images of x, y, z
        return quat_log(quat_from_matrix(rot))


# ---------------------------------------------------------------------------
# file encodings


def _as_unit_interval(rgb: np.ndarray, what: str) -> np.ndarray:
    arr = np.asarray(rgb)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"{what}: expected 3 channel(s) on the last axis, got shape {arr.shape}")
    if np.issubdtype(arr.dtype, np.integer):
        return (arr / np.float32(np.iinfo(arr.dtype).max)).astype(np.float32)
    return arr.astype(np.float32, copy=False)


def decode_normal_map(
    rgb: np.ndarray, *, convention: Convention = "opengl", in_place: bool = False
) -> np.ndarray:
    """Normal-map pixels (..., 3) -> unit OpenGL tangent-space normals (..., 3), float32.

    ``rgb`` is float in [0, 1] (integer arrays are divided by their dtype's
    maximum, e.g. 255 for uint8). ``n = 2 rgb - 1``; for ``"directx"`` files the
    green channel is flipped (their +Y points down the image); the result is
    renormalised, and zero-length pixels decode to the flat normal ``+z``.
    ``in_place``: written over ``rgb`` when it is C-contiguous float32 (a loader's
    own pixels, not needed after: no second full-size array to map).
    """
    _check_convention(convention)
    pixels = _as_unit_interval(rgb, "decode_normal_map")
    reuse = in_place and pixels is rgb and rgb.dtype == np.float32 and rgb.flags.c_contiguous
    return _rows_through(decode_normals, pixels, convention, out=rgb if reuse else None)


def encode_normal_map(normal: np.ndarray, *, convention: Convention = "opengl") -> np.ndarray:
    """Unit OpenGL normals (..., 3) -> file pixels ``rgb = (n + 1) / 2`` in [0, 1], float32.

    The normal is renormalised first (zero length -> ``+z``); ``"directx"``
    flips green. Quantising to 8 or 16 bits is the writer's job.
    """
    _check_convention(convention)
    return _rows_through(encode_normals, as_channels(normal, 3, "encode_normal_map"), convention)


def _rows_through(
    kernel, v: np.ndarray, convention: Convention, out: np.ndarray | None = None
) -> np.ndarray:
    """``kernel(rows, sign_y, tiny, out)`` over the 3-vectors of float32 ``v``, into a
    new array or ``out`` (``v`` itself: the kernels read a texel whole before writing it).

    A 2K map is decoded or encoded in one pass into one new array (numpy took
    three to five full-size temporaries, each a fresh allocation to fault in).
    """
    rows = np.ascontiguousarray(v).reshape(-1, 3)
    out_rows = np.empty_like(rows) if out is None else out.reshape(-1, 3)
    kernel(rows, _F32(-1.0 if convention == "directx" else 1.0), _TINY_LENGTH, out_rows)
    return out_rows.reshape(v.shape)


def _height_image(height: np.ndarray) -> np.ndarray:
    h = np.asarray(height)
    if h.ndim == 2:
        return h.astype(np.float32, copy=False)
    if h.ndim >= 3 and h.shape[-1] == 1:
        return h[..., 0].astype(np.float32, copy=False)
    raise ValueError(
        f"height_to_normal: expected a height image (H, W) or (..., H, W, 1), got shape {h.shape}"
    )


def height_to_normal(height: np.ndarray, *, strength: float = 1.0, wrap: bool = True) -> np.ndarray:
    """Height/bump map -> unit OpenGL tangent-space normals ``(..., H, W, 3)``, float32.

    ``height`` is ``(H, W)`` or ``(..., H, W, 1)``; a value ``h`` means a
    displacement of ``strength * h`` texel widths. With ``u`` along columns
    (rightwards) and ``v`` up the image (against the row index)::

        dh/du[i, j] = (h[i, j+1] - h[i, j-1]) / 2
        dh/dv[i, j] = (h[i-1, j] - h[i+1, j]) / 2      # row i-1 is *above* row i
        n ∝ (-strength dh/du, -strength dh/dv, 1)

    so a linear ramp ``h = a * column`` gives ``n = (-k a, 0, 1)/sqrt(1 + (k a)^2)``,
    a tilt of ``atan(k a)`` away from the uphill side. ``wrap=True`` treats the
    texture as tiling (periodic differences); ``wrap=False`` uses one-sided
    differences on the border texels (a ramp keeps its slope up to the edge).
    """
    h = _height_image(height)
    if h.shape[-1] < 2 or h.shape[-2] < 2:
        raise ValueError(f"height_to_normal: need at least 2x2 texels, got shape {h.shape[-2:]}")
    k = _F32(strength)
    if wrap:
        dh_du = _F32(0.5) * (np.roll(h, -1, axis=-1) - np.roll(h, 1, axis=-1))
        dh_dv = _F32(0.5) * (np.roll(h, 1, axis=-2) - np.roll(h, -1, axis=-2))
    else:
        dh_du = np.gradient(h, axis=-1).astype(np.float32, copy=False)
        dh_dv = -np.gradient(h, axis=-2).astype(np.float32, copy=False)
    n = np.stack([-k * dh_du, -k * dh_dv, np.ones_like(h)], axis=-1)
    return _normalize_or_z(n)


SPACES: dict[str, Space] = {
    "normal": NormalFrameSpace(),
    "normal_tangent": NormalTangentFrameSpace(),
}
