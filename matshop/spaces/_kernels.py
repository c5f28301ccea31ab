"""numba kernels for the per-texel editing spaces (colors, scalars, GGX, Phong, frames).

Each kernel is one parallel pass over ``(N, C)`` float32 texels of any row
stride: it reads a band of a file map and writes straight into the edit
channels of a wider array (or back), with no temporaries beyond a few KiB of
scratch per thread. Arithmetic is float64 inside, float32 at the edges.

Everything lives in this one module on purpose: numba's on-disk cache
(``cache=True``) only notices edits to the file that defines a kernel, so
helpers inlined from another module could leave stale machine code behind.

Writing numba code that vectorises (LLVM, AVX2 / AVX-512; no SVML here, so a
call to ``math.atan2``, ``math.pow``, ``math.sin`` ... stays a scalar libm
call and blocks vectorisation of its loop):

* The transcendental functions below use only arithmetic, ``sqrt``, bit
  casts and selects, accurate to about 1e-10 relative, far below the float32
  rounding of the inputs and outputs (tests/test_kernels.py checks them
  against numpy in float64). The sRGB curves, the hot spot, are rational
  functions on [-1, 1] and fall back to ``exp(p log x)`` only for blocks
  holding values beyond.
* ``error_model="numpy"``: the default Python error model tests every
  division for zero and raises, which blocks vectorisation.
* Unsigned indices: numba's wraparound fix-up for possibly negative signed
  indices makes addresses non-affine.
* Branch-free loop bodies: conditional expressions on scalars become selects.
* Only the ``contract`` fast-math flag (fused multiply-add), never ``nnan`` /
  ``ninf`` (NaN handling relies on comparisons) or ``reassoc`` (it would undo
  the argument reductions and the rounding trick).
* Strided loads and stores with a run-time stride do not vectorise, so
  :data:`BLOCK` texels at a time are copied into per-thread planar float64
  scratch, transformed there, and copied out. Tightly packed rows take
  dedicated copy loops with compile-time strides, which LLVM does vectorise.
* The thread count is passed in (:func:`chunks`): numba cannot cache a
  kernel that asks for it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np
from numba import get_num_threads, njit, prange
from numpy.lib.stride_tricks import as_strided

from ..parallel_chunks import next_chunk

#: options of the scalar helpers (inlined into the kernels)
_INLINE = {"inline": "always", "error_model": "numpy", "fastmath": {"contract"}, "nogil": True}
#: options of the workers (a parallel kernel calls one per chunk, a chunk a few
#: per block): each compiled on its own, which keeps numba's parfor lowering
#: small; one function holding everything compiles several times slower
_WORKER = {"cache": True, "error_model": "numpy", "fastmath": {"contract"}, "nogil": True}
#: options of the kernels
_KERNEL = {
    "parallel": True,
    "cache": True,
    "error_model": "numpy",
    "fastmath": {"contract"},
    "nogil": True,
}

#: texels per scratch block (planar float64: 4 KiB per channel)
BLOCK = 512
#: fewer texels than this per parallel chunk are not worth a thread hand-off
_MIN_CHUNK = 8 * BLOCK
#: chunks per thread at most: enough that the threads end together when one is held up
_CHUNKS_PER_THREAD = 16

_U = np.uint64
_PI = math.pi
_HALF_PI = 0.5 * math.pi
_QUARTER_PI = 0.25 * math.pi
_TAN_PI_8 = math.tan(math.pi / 8.0)
_INF = math.inf
_TINY_SQUARED = 1e-24  # frame.py's _TINY_LENGTH squared

# atan(u) / u as a polynomial in z = u^2 on [0, tan^2(pi/8)] (Chebyshev fit,
# max |atan error| 8e-12)
_AT0 = 0.9999999999791593
_AT1 = -0.3333333212831546
_AT2 = 0.19999885915281318
_AT3 = -0.1428163951660222
_AT4 = 0.11041055935233751
_AT5 = -0.08459114071430666
_AT6 = 0.04713000031737973

# fdlibm __kernel_sin / __kernel_cos on [-pi/4, pi/4]
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11

# fdlibm's medium-size reduction: pi/2 = _PIO2_1 + _PIO2_1T, where _PIO2_1 has
# 33 significant bits, so k * _PIO2_1 is exact for k < 2^20
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_1T = 6.07710050650619224932e-11

# ln m = 2 atanh(f), f = (m - 1) / (m + 1), |f| <= 0.1716 for m in
# [sqrt(1/2), sqrt(2)]: the series 2f (1 + f^2/3 + ... + f^10/11) is off by 2e-11
_SQRT2 = math.sqrt(2.0)
_LN2_HI = 6.93147180369123816490e-01  # fdlibm: ln 2 = _LN2_HI + _LN2_LO, k * _LN2_HI exact
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.44269504088896338700e00
_MANTISSA = np.int64(0x000FFFFFFFFFFFFF)
_EXP_ONE = np.int64(0x3FF0000000000000)
# adding 1.5 * 2^52 rounds a double (|x| < 2^51) to an integer, which then
# sits in the low mantissa bits
_ROUND = 6755399441055744.0
_ROUND_BITS = np.int64(0x4338000000000000)


# ---------------------------------------------------------------------------
# scalar math (float64, branch-free)


@njit(**_INLINE)
def atan_unit(t):
    """``atan(t)`` for ``0 <= t <= 1``."""
    big = t > _TAN_PI_8
    u = (t - 1.0) / (t + 1.0) if big else t
    z = u * u
    a = u * (_AT0 + z * (_AT1 + z * (_AT2 + z * (_AT3 + z * (_AT4 + z * (_AT5 + z * _AT6))))))
    return a + _QUARTER_PI if big else a


@njit(**_INLINE)
def atan2_upper(y, x):
    """``atan2(y, x)`` for ``y >= 0``, in ``[0, pi]``; ``(0, 0)`` gives 0."""
    ax = abs(x)
    swap = y > ax
    lo = ax if swap else y
    hi = y if swap else ax
    # one division: atan(lo / hi), reduced by pi/4 above tan(pi/8)
    big = lo > _TAN_PI_8 * hi
    u = (lo - hi) / (lo + hi) if big else lo / hi
    u = u if hi > 0.0 else 0.0
    z = u * u
    a = u * (_AT0 + z * (_AT1 + z * (_AT2 + z * (_AT3 + z * (_AT4 + z * (_AT5 + z * _AT6))))))
    a = a + _QUARTER_PI if big else a
    a = _HALF_PI - a if swap else a
    return _PI - a if x < 0.0 else a


@njit(**_INLINE)
def sin_small(r, z):
    """``sin(r)`` for ``|r| <= pi/4``, given ``z = r * r``."""
    return r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))


@njit(**_INLINE)
def cos_small(z):
    """``cos(r)`` for ``|r| <= pi/4``, given ``z = r * r``."""
    return 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))


@njit(**_INLINE)
def cos_sinc(phi):
    """``(cos(phi), sin(phi) / phi)`` for finite ``phi >= 0`` (``sinc(0) = 1``).

    Accurate to about 1e-15 up to ``phi ~ 1e6`` (the limit of the one-step
    reduction by pi/2); larger arguments give an inexact pair, still with
    ``cos^2 + (phi sinc)^2 = 1``.
    """
    rounded = phi * _INV_PIO2 + _ROUND
    k = rounded - _ROUND
    r = (phi - k * _PIO2_1) - k * _PIO2_1T
    # only huge phi (past 2^50) leave [-pi/4, pi/4]: keep the pair unit length
    r = -_QUARTER_PI if r < -_QUARTER_PI else r
    r = _QUARTER_PI if r > _QUARTER_PI else r
    z = r * r
    s = sin_small(r, z)
    c = cos_small(z)
    # quadrant q: (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s) for q = 0, 1, 2, 3
    # mod 4 (flat selects: a nested conditional chain would not vectorise)
    q = np.float64(rounded).view(np.int64) - _ROUND_BITS
    odd = (q & 1) == 1
    sin_phi = c if odd else s
    cos_phi = s if odd else c
    sin_phi = -sin_phi if (q & 2) == 2 else sin_phi
    cos_phi = -cos_phi if ((q + 1) & 2) == 2 else cos_phi
    # below pi/4, sin(phi) / phi is the series itself (no 0 / 0 at phi = 0)
    sinc = 1.0 + z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    return cos_phi, sinc if k == 0.0 else sin_phi / phi


@njit(**_INLINE)
def log_pos(x):
    """Natural log of a finite ``x > 0``, absolute error about 2e-11."""
    bits = np.float64(x).view(np.int64)
    e = np.float64((bits >> 52) - 1023)
    m = np.int64((bits & _MANTISSA) | _EXP_ONE).view(np.float64)  # in [1, 2)
    big = m > _SQRT2
    m = 0.5 * m if big else m
    e = e + 1.0 if big else e
    f = (m - 1.0) / (m + 1.0)
    s = f * f
    series = s * (
        2.0 / 3.0 + s * (2.0 / 5.0 + s * (2.0 / 7.0 + s * (2.0 / 9.0 + s * (2.0 / 11.0))))
    )
    return e * _LN2_HI + (2.0 * f + f * series + e * _LN2_LO)


@njit(**_INLINE)
def exp_clamped(t):
    """``exp(t)``, relative error below 5e-13; ``t`` is clamped to [-700, 700] (NaN to -700)."""
    t = t if t > -700.0 else -700.0
    t = t if t < 700.0 else 700.0
    rounded = t * _INV_LN2 + _ROUND
    k = rounded - _ROUND
    r = (t - k * _LN2_HI) - k * _LN2_LO  # |r| <= 0.347
    # Taylor series to r^10 (Horner)
    p = 1.0 / 3628800.0
    p = p * r + 1.0 / 362880.0
    p = p * r + 1.0 / 40320.0
    p = p * r + 1.0 / 5040.0
    p = p * r + 1.0 / 720.0
    p = p * r + 1.0 / 120.0
    p = p * r + 1.0 / 24.0
    p = p * r + 1.0 / 6.0
    p = p * r + 0.5
    p = p * r + 1.0
    p = p * r + 1.0
    k_int = np.float64(rounded).view(np.int64) - _ROUND_BITS
    return p * np.int64((k_int + 1023) << 52).view(np.float64)


@njit(**_INLINE)
def pow_pos(x, p):
    """``x ** p`` for finite ``x > 0`` with ``|p ln x| < 700``, relative error about 1e-10."""
    return exp_clamped(p * log_pos(x))


# ---------------------------------------------------------------------------
# moving blocks of texels between strided float32 rows and planar float64 scratch


@njit(**_WORKER)
def _load(src, stride, channels, first, count, buf):
    """``buf[c, k] = src[(first + k) * stride + c]`` for ``k < count``, ``c < channels``.

    Packed rows of one, two, three and six channels get loops with compile-time
    strides, which vectorise; strided rows of one to three channels get loops
    without the inner channel loop (several times faster than the generic one:
    two-channel maps, the Ashikhmin-Shirley exponents, took the generic loop and
    their fused to_edit 1.4x their step alone).
    """
    if channels == 1:
        if stride == 1:
            for k in range(count):
                buf[0, k] = src[first + k]
        else:
            for k in range(count):
                buf[0, k] = src[stride * (first + k)]
    elif channels == 2 and stride == 2:
        for k in range(count):
            i = _U(2) * (first + k)
            buf[0, k] = src[i]
            buf[1, k] = src[i + _U(1)]
    elif channels == 2:
        for k in range(count):
            i = stride * (first + k)
            buf[0, k] = src[i]
            buf[1, k] = src[i + _U(1)]
    elif channels == 3 and stride == 3:
        for k in range(count):
            i = _U(3) * (first + k)
            buf[0, k] = src[i]
            buf[1, k] = src[i + _U(1)]
            buf[2, k] = src[i + _U(2)]
    elif channels == 3:
        for k in range(count):
            i = stride * (first + k)
            buf[0, k] = src[i]
            buf[1, k] = src[i + _U(1)]
            buf[2, k] = src[i + _U(2)]
    elif channels == 6 and stride == 6:
        for k in range(count):
            i = _U(6) * (first + k)
            buf[0, k] = src[i]
            buf[1, k] = src[i + _U(1)]
            buf[2, k] = src[i + _U(2)]
            buf[3, k] = src[i + _U(3)]
            buf[4, k] = src[i + _U(4)]
            buf[5, k] = src[i + _U(5)]
    else:
        for k in range(count):
            i = stride * (first + k)
            for c in range(channels):
                buf[c, k] = src[i + c]


@njit(**_WORKER)
def _store(buf, channels, first, count, dst, stride):
    """``dst[(first + k) * stride + c] = buf[c, k]`` for ``k < count``, ``c < channels``."""
    if channels == 1:
        if stride == 1:
            for k in range(count):
                dst[first + k] = buf[0, k]
        else:
            for k in range(count):
                dst[stride * (first + k)] = buf[0, k]
    elif channels == 2 and stride == 2:
        for k in range(count):
            i = _U(2) * (first + k)
            dst[i] = buf[0, k]
            dst[i + _U(1)] = buf[1, k]
    elif channels == 2:
        for k in range(count):
            i = stride * (first + k)
            dst[i] = buf[0, k]
            dst[i + _U(1)] = buf[1, k]
    elif channels == 3 and stride == 3:
        for k in range(count):
            i = _U(3) * (first + k)
            dst[i] = buf[0, k]
            dst[i + _U(1)] = buf[1, k]
            dst[i + _U(2)] = buf[2, k]
    elif channels == 3:
        for k in range(count):
            i = stride * (first + k)
            dst[i] = buf[0, k]
            dst[i + _U(1)] = buf[1, k]
            dst[i + _U(2)] = buf[2, k]
    elif channels == 6 and stride == 6:
        for k in range(count):
            i = _U(6) * (first + k)
            dst[i] = buf[0, k]
            dst[i + _U(1)] = buf[1, k]
            dst[i + _U(2)] = buf[2, k]
            dst[i + _U(3)] = buf[3, k]
            dst[i + _U(4)] = buf[4, k]
            dst[i + _U(5)] = buf[5, k]
    else:
        for k in range(count):
            i = stride * (first + k)
            for c in range(channels):
                dst[i + c] = buf[c, k]


# ---------------------------------------------------------------------------
# per-channel transfer functions (colors, GGX roughness, linear scalars)

#: curve codes of :func:`transfer`
IDENTITY = 0  # clamp only
SRGB_DECODE = 1  # IEC 61966-2-1 decode, odd-symmetric
SRGB_ENCODE = 2  # IEC 61966-2-1 encode, odd-symmetric
POWER = 3  # x ** p for x > 0, 0 for x <= 0 (clamp with lo >= 0 first)
ATAN_SQUARE = 4  # atan(x^2) (GGX median angle; clamp to [0, 1] first)
SQRT_TAN = 5  # sqrt(clamp(tan x, 0, 1)) (clamp to [0, pi/4] first)
SQUARE = 6  # x^2
SQRT = 7  # sqrt(x) (clamp with lo >= 0 first)
PHONG_MEDIAN_TO_EDIT = 8  # exponent n -> median angle acos(2^(-1/(n+2))) (lo >= 0)
PHONG_MEDIAN_FROM_EDIT = 9  # median angle -> -ln 2 / ln cos e - 2, clamped to [0, p]

_SRGB_DECODE_KNEE = 0.04045
_SRGB_ENCODE_KNEE = 0.0031308

# The sRGB curves on [knee, 1] as rational functions N(t) / D(t), t in [-1, 1]:
# decode in t = (v - c) / h, type (7, 7); encode in t = (sqrt(x) - c) / h, type
# (8, 8). Fitted with scipy.interpolate.AAA (8 and 9 support points on a
# uniform grid of the interval) and expanded into monomials in t; relative
# error below 6e-11 for every float32 input in the interval (checked
# exhaustively against numpy in float64 when fitted; tests/test_kernels.py
# checks a dense grid), with D > 0 throughout. Two to three times faster than
# log + exp; blocks holding values beyond +-1 (or NaN, inf) take that path.
_DEC_C = 0.520225
_DEC_INV_H = 2.0843103538116825
_DEC_N = (
    0.23324089729863678,
    0.9918099584604116,
    1.7589015840994842,
    1.6767328994937147,
    0.9206409514432109,
    0.28784990629804774,
    0.0466285947027483,
    0.002931305160785233,
)
_DEC_D = (
    1.0,
    2.2505428399869056,
    1.8673838002550367,
    0.6905827596148363,
    0.10610290648525984,
    0.00419309317309903,
    -7.146161754924704e-05,
    2.159059450356731e-06,
)
_ENC_C = 0.5279767760830301
_ENC_INV_H = 2.1185398288282156
_ENC_N = (
    0.5645810735261139,
    2.642219444917153,
    5.20218277780886,
    5.5805378947342,
    3.525086201071248,
    1.3190862298388049,
    0.2776119570814603,
    0.02858163863547507,
    0.0009923632968031704,
)
_ENC_D = (
    1.0,
    3.862367914864362,
    6.11728840799327,
    5.097001030480278,
    2.3775074419155304,
    0.6072805198924396,
    0.07599277271782655,
    0.0034298218118308486,
    1.16712345818565e-05,
)


@njit(**_INLINE)
def _poly7(t, c):
    return c[0] + t * (
        c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * (c[5] + t * (c[6] + t * c[7])))))
    )


@njit(**_INLINE)
def _poly8(t, c):
    return c[0] + t * _poly7(t, c[1:])


@njit(**_INLINE)
def _srgb_decode_unit(v):
    """:func:`_srgb_decode` for ``|v| <= 1`` (rational function, no log / exp)."""
    mag = abs(v)
    t = (mag - _DEC_C) * _DEC_INV_H
    curve = _poly7(t, _DEC_N) / _poly7(t, _DEC_D)
    out = mag * (1.0 / 12.92) if mag <= _SRGB_DECODE_KNEE else curve
    return math.copysign(out, v)


@njit(**_INLINE)
def _srgb_encode_unit(v):
    """:func:`_srgb_encode` for ``|v| <= 1`` (rational function of ``sqrt(v)``)."""
    mag = abs(v)
    t = (math.sqrt(mag) - _ENC_C) * _ENC_INV_H
    curve = _poly8(t, _ENC_N) / _poly8(t, _ENC_D)
    out = mag * 12.92 if mag <= _SRGB_ENCODE_KNEE else curve
    return math.copysign(out, v)


@njit(**_INLINE)
def _srgb_decode(v):
    mag = abs(v)
    curve = pow_pos((mag + 0.055) * (1.0 / 1.055), 2.4)
    out = mag * (1.0 / 12.92) if mag <= _SRGB_DECODE_KNEE else curve
    out = out if mag < _INF else mag  # inf stays inf, NaN stays NaN
    return math.copysign(out, v)


@njit(**_INLINE)
def _srgb_encode(v):
    mag = abs(v)
    curve = 1.055 * pow_pos(mag, 1.0 / 2.4) - 0.055
    out = mag * 12.92 if mag <= _SRGB_ENCODE_KNEE else curve
    out = out if mag < _INF else mag
    return math.copysign(out, v)


@njit(**_INLINE)
def _power(v, p):
    out = pow_pos(v, p) if v > 0.0 else 0.0
    return out if v < _INF else v


@njit(**_INLINE)
def _sqrt_tan(e):
    z = e * e
    t = sin_small(e, z) / cos_small(z)
    t = 1.0 if t > 1.0 else t
    return math.sqrt(0.0 if t < 0.0 else t)  # NaN stays NaN


@njit(**_INLINE)
def _clamp(v, lo, hi):
    v = lo if v < lo else v
    return hi if v > hi else v  # NaN stays NaN


# one worker per curve: compiled separately (a single function holding every
# curve compiles several times slower), each called once per block


@njit(**_INLINE)
def _clamp_and_count_outside_unit(row, count, lo, hi):
    """Clamp ``row[:count]`` in place; how many values are not within [-1, 1] (NaN counts)."""
    outside = 0
    for k in range(count):
        x = _clamp(row[k], lo, hi)
        row[k] = x
        outside += 0 if abs(x) <= 1.0 else 1
    return outside


@njit(**_WORKER)
def _curve_srgb_decode(row, count, lo, hi, p):
    if _clamp_and_count_outside_unit(row, count, lo, hi) == 0:
        for k in range(count):
            row[k] = _srgb_decode_unit(row[k])
    else:
        for k in range(count):
            row[k] = _srgb_decode(row[k])


@njit(**_WORKER)
def _curve_srgb_encode(row, count, lo, hi, p):
    if _clamp_and_count_outside_unit(row, count, lo, hi) == 0:
        for k in range(count):
            row[k] = _srgb_encode_unit(row[k])
    else:
        for k in range(count):
            row[k] = _srgb_encode(row[k])


@njit(**_WORKER)
def _curve_power(row, count, lo, hi, p):
    for k in range(count):
        row[k] = _power(_clamp(row[k], lo, hi), p)


@njit(**_WORKER)
def _curve_atan_square(row, count, lo, hi, p):
    for k in range(count):
        x = _clamp(row[k], lo, hi)
        row[k] = atan_unit(x * x)


@njit(**_WORKER)
def _curve_sqrt_tan(row, count, lo, hi, p):
    for k in range(count):
        row[k] = _sqrt_tan(_clamp(row[k], lo, hi))


@njit(**_WORKER)
def _curve_simple(row, count, curve, lo, hi):
    """IDENTITY, SQUARE and SQRT (cheap enough to share one worker)."""
    if curve == SQUARE:
        for k in range(count):
            x = _clamp(row[k], lo, hi)
            row[k] = x * x
    elif curve == SQRT:
        for k in range(count):
            row[k] = math.sqrt(_clamp(row[k], lo, hi))
    else:
        for k in range(count):
            row[k] = _clamp(row[k], lo, hi)


# The Phong median angle e = acos(2^(-1/(n+2))) and back, each as a closed part times
# a smooth polynomial (scripts/fit_phong_median.py fits them to 50-digit values; largest
# relative error in the comment): one reciprocal square root to the edit space (float32's,
# refined by one float64 Newton step: 0.94 of the time of float64's square root and
# division), one division back (the same refined estimate measured 1.15x slower there).

# e = sqrt(x) G(x), x = 1/(n + 2) in [0, 1/2]: degree 7, 8.9e-15
_PHONG_G = (
    1.1774100225154842,
    -0.13601973958071018,
    0.004714085049177409,
    0.0011669822695229359,
    -4.7173608160635394e-05,
    -2.8293959163284484e-05,
    9.23071920303804e-07,
    7.529243477498661e-07,
)
# n = S(e) (pi/4 - e) / e^2 on [0, pi/4]: degree 12, 8e-13; the factor pi/4 - e holds
# the zero at n = 0, so near it no difference of nearly equal numbers is left
_PHONG_S = (
    1.7650848012226286,
    2.247375768104763,
    0.020787855637381485,
    0.02646661182039541,
    0.004299876314627486,
    0.005298787644510594,
    0.0019289403201900777,
    -0.0015275377311081669,
    0.007331937224852006,
    -0.010784459814211795,
    0.011627039826358241,
    -0.006904314592555776,
    0.0020373632766450076,
)
# pi/4 as a sum of two doubles: pi/4 - e keeps its digits when e is near pi/4
_QUARTER_PI_HI = 0.25 * math.pi
_QUARTER_PI_LO = 3.061616997868383e-17
# beyond this n + 2 the float32 estimate is 0 (not inf * 0 in the Newton step)
_HUGE = 1e300


@njit(**_INLINE)
def _rsqrt(y):
    """``1 / sqrt(y)`` for ``y >= 2`` (inf gives 0): relative error about 2e-14."""
    y = min(y, _HUGE)  # NaN stays NaN
    r = np.float64(np.float32(1.0) / np.sqrt(np.float32(y)))
    return r * (1.5 - (0.5 * y) * (r * r))


@njit(**_INLINE)
def _phong_median_to_edit(n):
    """``2 asin(sqrt((1 - 2^(-1/(n+2))) / 2))``, the median angle of ``cos^n``, as
    ``r G(r^2)`` with ``r = 1 / sqrt(n + 2)``; ``n = inf`` gives 0, NaN stays NaN."""
    r = _rsqrt(n + 2.0)
    x = r * r
    x2 = x * x
    g = _PHONG_G
    low = (g[0] + x * g[1]) + x2 * (g[2] + x * g[3])
    high = (g[4] + x * g[5]) + x2 * (g[6] + x * g[7])
    return r * (low + (x2 * x2) * high)


@njit(**_INLINE)
def _phong_median_from_edit(e, p):
    """``-ln 2 / ln(cos e) - 2`` clamped to ``[0, p]``, for ``e`` in ``[median(p),
    float32(pi/4)]`` (the kernel's clamp): ``S(e) (pi/4 - e) / e^2``."""
    k = _PHONG_S
    e2 = e * e
    e4 = e2 * e2
    e8 = e4 * e4
    low = ((k[0] + e * k[1]) + e2 * (k[2] + e * k[3])) + e4 * (
        (k[4] + e * k[5]) + e2 * (k[6] + e * k[7])
    )
    high = ((k[8] + e * k[9]) + e2 * (k[10] + e * k[11])) + e4 * k[12]
    d = (_QUARTER_PI_HI - e) + _QUARTER_PI_LO
    return _clamp((low + e8 * high) * d / e2, 0.0, p)


# The two Phong median loops take the row's halves side by side: each value is a chain
# of dependent operations, and two independent chains a step keep the out-of-order
# core busy where one left it waiting (to the edit space 0.81 of the old kernel's time
# in one value a step, 0.74 in two).


@njit(**_WORKER)
def _curve_phong_median_to_edit(row, count, lo, hi, p):
    half = count // 2
    for k in range(half):
        a = _phong_median_to_edit(_clamp(row[k], lo, hi))
        b = _phong_median_to_edit(_clamp(row[k + half], lo, hi))
        row[k] = a
        row[k + half] = b
    if count % 2:
        row[count - 1] = _phong_median_to_edit(_clamp(row[count - 1], lo, hi))


@njit(**_WORKER)
def _curve_phong_median_from_edit(row, count, lo, hi, p):
    """``e`` clamped to ``[lo, hi]`` (within (0, pi/4]) to exponents in ``[0, p]``."""
    half = count // 2
    for k in range(half):
        a = _phong_median_from_edit(_clamp(row[k], lo, hi), p)
        b = _phong_median_from_edit(_clamp(row[k + half], lo, hi), p)
        row[k] = a
        row[k + half] = b
    if count % 2:
        row[count - 1] = _phong_median_from_edit(_clamp(row[count - 1], lo, hi), p)


@njit(**_WORKER)
def _apply_curve(buf, channels, count, curve, lo, hi, p):
    """Clamp and map ``buf[:channels, :count]`` in place."""
    for c in range(channels):
        row = buf[c]
        if curve == SRGB_DECODE:
            _curve_srgb_decode(row, count, lo, hi, p)
        elif curve == SRGB_ENCODE:
            _curve_srgb_encode(row, count, lo, hi, p)
        elif curve == POWER:
            _curve_power(row, count, lo, hi, p)
        elif curve == ATAN_SQUARE:
            _curve_atan_square(row, count, lo, hi, p)
        elif curve == SQRT_TAN:
            _curve_sqrt_tan(row, count, lo, hi, p)
        elif curve == PHONG_MEDIAN_TO_EDIT:
            _curve_phong_median_to_edit(row, count, lo, hi, p)
        elif curve == PHONG_MEDIAN_FROM_EDIT:
            _curve_phong_median_from_edit(row, count, lo, hi, p)
        else:
            _curve_simple(row, count, curve, lo, hi)


@njit(**_WORKER)
def _transfer_chunk(src, src_stride, dst, dst_stride, start, stop, channels, curve, lo, hi, p):
    buf = np.empty((channels, BLOCK), dtype=np.float64)
    for first in range(_U(start), _U(stop), _U(BLOCK)):
        count = min(_U(BLOCK), _U(stop) - first)
        _load(src, _U(src_stride), _U(channels), first, count, buf)
        _apply_curve(buf, _U(channels), count, curve, lo, hi, p)
        _store(buf, _U(channels), first, count, dst, _U(dst_stride))


@njit(**_KERNEL)
def _transfer_kernel(
    src, src_stride, dst, dst_stride, n, channels, curve, lo, hi, p, nchunks, workers, taken
):
    for _worker in prange(workers):
        chunk = next_chunk(taken)
        while chunk < nchunks:
            start, stop = _chunk_bounds(chunk, n, nchunks)
            _transfer_chunk(
                src, src_stride, dst, dst_stride, start, stop, channels, curve, lo, hi, p
            )
            chunk = next_chunk(taken)


# ---------------------------------------------------------------------------
# local frames (MATH.md "Local frames"; frame.py has the numpy reference)

#: frame kernel codes
NORMAL_TO_EDIT = 0  # normal (3) -> log of the smallest rotation z -> n (3)
NORMAL_FROM_EDIT = 1  # log rotation (3) -> R z (3)
FRAME_TO_EDIT = 2  # normal + tangent (6) -> log rotation (3)
FRAME_FROM_EDIT = 3  # log rotation (3) -> (R z, R x) (6)
#: channels in and out per frame code
FRAME_CHANNELS = ((3, 3), (3, 3), (6, 3), (3, 6))


@njit(**_INLINE)
def _normal_log(x, y, z):
    """``ln q`` of the smallest rotation taking ``z`` to the direction of ``(x, y, z)``.

    Returns ``(ex, ey)`` (``ez`` is 0): ``(-y, x) / s * atan2(s, z) / 2`` with
    ``s = |(x, y)|``, which does not depend on the length of the vector, so it
    is never normalised. Zero (below frame.py's 1e-12), infinite or NaN
    vectors count as ``+z``; exactly ``-z`` is the half turn about ``x``.
    """
    l2 = x * x + y * y + z * z
    ok = (l2 > _TINY_SQUARED) & (l2 < _INF)
    s2 = x * x + y * y
    s = math.sqrt(s2)
    flat = s2 <= 1e-60 * l2  # sin(tilt) <= 1e-30
    ratio = 0.5 * atan2_upper(s, z) / s
    ratio = 0.5 if flat else ratio
    ex = -y * ratio
    ex = _HALF_PI if flat & (z < 0.0) else ex
    return (ex if ok else 0.0), (x * ratio if ok else 0.0)


@njit(**_INLINE)
def _quat_exp(ex, ey, ez):
    """``exp`` of the pure quaternion ``(ex, ey, ez)``: ``(w, x, y, z)``, unit up to rounding.

    Non-finite input gives the identity. Beyond ``|e| ~ 1e6`` the argument
    reduction is inexact and ``|q|`` may drift from 1: the rotation helpers
    below are homogeneous in ``q``, so callers divide by ``|q|^2``.
    """
    phi2 = ex * ex + ey * ey + ez * ez
    ok = phi2 < _INF  # false for inf and NaN
    phi = math.sqrt(phi2 if ok else 0.0)
    w, sinc = cos_sinc(phi)
    return w, (sinc * ex if ok else 0.0), (sinc * ey if ok else 0.0), (sinc * ez if ok else 0.0)


@njit(**_INLINE)
def _rotate_z(w, x, y, z):
    """``|q|^2 R(q) z``: the third column of the rotation matrix, times ``|q|^2``."""
    return 2.0 * (x * z + w * y), 2.0 * (y * z - w * x), (w * w + z * z) - (x * x + y * y)


@njit(**_INLINE)
def _rotate_x(w, x, y, z):
    """``|q|^2 R(q) x``: the first column of the rotation matrix, times ``|q|^2``."""
    return (w * w + x * x) - (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y)


@njit(**_INLINE)
def _normal_from_log(ex, ey, ez):
    w, x, y, z = _quat_exp(ex, ey, ez)
    nx, ny, nz = _rotate_z(w, x, y, z)
    inv = 1.0 / (w * w + x * x + y * y + z * z)
    return nx * inv, ny * inv, nz * inv


@njit(**_INLINE)
def _frame_log(nx, ny, nz, tx, ty, tz):
    """``ln q`` of the rotation taking ``(x, y, z)`` to ``(t', n x t', n)``.

    ``n`` is normalised (zero / non-finite: ``+z``); ``t'`` is ``t``
    Gram-Schmidt orthonormalised against ``n``. When ``t`` is zero or within
    about 1e-3 rad of ``+-n`` the frame is the smallest rotation of ``n``.
    Shepperd's method picks the best-conditioned quaternion component.
    """
    l2 = nx * nx + ny * ny + nz * nz
    ok = (l2 > _TINY_SQUARED) & (l2 < _INF)
    inv = 1.0 / math.sqrt(l2)
    nx = nx * inv if ok else 0.0
    ny = ny * inv if ok else 0.0
    nz = nz * inv if ok else 1.0
    t_len = math.sqrt(tx * tx + ty * ty + tz * tz)
    dot = tx * nx + ty * ny + tz * nz
    tx -= dot * nx
    ty -= dot * ny
    tz -= dot * nz
    perp = math.sqrt(tx * tx + ty * ty + tz * tz)
    limit = 1e-3 * t_len
    usable = perp > (limit if limit > 1e-12 else 1e-12)  # false for NaN tangents too
    inv = 1.0 / perp
    tx *= inv
    ty *= inv
    tz *= inv
    dot = tx * nx + ty * ny + tz * nz  # second pass against cancellation
    tx -= dot * nx
    ty -= dot * ny
    tz -= dot * nz
    inv = 1.0 / math.sqrt(tx * tx + ty * ty + tz * tz)
    tx *= inv
    ty *= inv
    tz *= inv
    bx = ny * tz - nz * ty
    by = nz * tx - nx * tz
    bz = nx * ty - ny * tx
    # columns t, b, n: r00 = tx, r01 = bx, r02 = nx, r10 = ty, ...
    four_w = 1.0 + tx + by + nz
    four_x = 1.0 + tx - by - nz
    four_y = 1.0 - tx + by - nz
    four_z = 1.0 - tx - by + nz
    # the largest of the four (the first one on ties, like np.argmax)
    one = four_x > four_w
    best = four_x if one else four_w
    two = four_y > best
    best = four_y if two else best
    three = four_z > best
    best = four_z if three else best
    big = 0.5 * math.sqrt(best if best > 0.0 else 0.0)
    quarter = 0.25 / (big if big > 1e-30 else 1e-30)
    zy = (bz - ny) * quarter  # (r21 - r12)
    xz = (nx - tz) * quarter  # (r02 - r20)
    yx = (ty - bx) * quarter  # (r10 - r01)
    pxy = (bx + ty) * quarter  # (r01 + r10)
    pxz = (nx + tz) * quarter  # (r02 + r20)
    pyz = (ny + bz) * quarter  # (r12 + r21)
    # flat selects per case (a nested conditional chain would not vectorise)
    w, x, y, z = big, zy, xz, yx
    w = zy if one else w
    x = big if one else x
    y = pxy if one else y
    z = pxz if one else z
    w = xz if two else w
    x = pxy if two else x
    y = big if two else y
    z = pyz if two else z
    w = yx if three else w
    x = pxz if three else x
    y = pyz if three else y
    z = big if three else z
    sign = -1.0 if w < 0.0 else 1.0
    inv = sign / math.sqrt(w * w + x * x + y * y + z * z)
    w *= inv
    x *= inv
    y *= inv
    z *= inv
    s = math.sqrt(x * x + y * y + z * z)
    ratio = atan2_upper(s, w) / s
    ratio = 1.0 if s <= 1e-30 else ratio
    ex, ey = _normal_log(nx, ny, nz)
    return (
        (x * ratio if usable else ex),
        (y * ratio if usable else ey),
        (z * ratio if usable else 0.0),
    )


# one worker per conversion, compiled separately (see the curves)


@njit(**_WORKER)
def _frame_normal_to_edit(buf, count):
    for k in range(count):
        ex, ey = _normal_log(buf[0, k], buf[1, k], buf[2, k])
        buf[0, k] = ex
        buf[1, k] = ey
        buf[2, k] = 0.0


@njit(**_WORKER)
def _frame_normal_from_edit(buf, count):
    for k in range(count):
        nx, ny, nz = _normal_from_log(buf[0, k], buf[1, k], buf[2, k])
        buf[0, k] = nx
        buf[1, k] = ny
        buf[2, k] = nz


@njit(**_WORKER)
def _frame_to_edit(buf, count):
    for k in range(count):
        ex, ey, ez = _frame_log(buf[0, k], buf[1, k], buf[2, k], buf[3, k], buf[4, k], buf[5, k])
        buf[0, k] = ex
        buf[1, k] = ey
        buf[2, k] = ez


@njit(**_WORKER)
def _frame_from_edit(buf, count):
    for k in range(count):
        w, x, y, z = _quat_exp(buf[0, k], buf[1, k], buf[2, k])
        nx, ny, nz = _rotate_z(w, x, y, z)
        tx, ty, tz = _rotate_x(w, x, y, z)
        inv = 1.0 / (w * w + x * x + y * y + z * z)
        buf[0, k] = nx * inv
        buf[1, k] = ny * inv
        buf[2, k] = nz * inv
        buf[3, k] = tx * inv
        buf[4, k] = ty * inv
        buf[5, k] = tz * inv


# normal maps and normal + tangent frames get kernels of their own, so a
# material with a normal map never compiles the larger frame conversions


@njit(**_WORKER)
def _apply_normal(buf, count, code):
    if code == NORMAL_TO_EDIT:
        _frame_normal_to_edit(buf, count)
    else:
        _frame_normal_from_edit(buf, count)


@njit(**_WORKER)
def _apply_frame(buf, count, code):
    if code == FRAME_TO_EDIT:
        _frame_to_edit(buf, count)
    else:
        _frame_from_edit(buf, count)


@njit(**_WORKER)
def _normal_chunk(src, src_stride, dst, dst_stride, start, stop, code):
    buf = np.empty((3, BLOCK), dtype=np.float64)
    for first in range(_U(start), _U(stop), _U(BLOCK)):
        count = min(_U(BLOCK), _U(stop) - first)
        _load(src, _U(src_stride), _U(3), first, count, buf)
        _apply_normal(buf, count, code)
        _store(buf, _U(3), first, count, dst, _U(dst_stride))


@njit(**_WORKER)
def _frame_chunk(src, src_stride, dst, dst_stride, start, stop, code, c_in, c_out):
    buf = np.empty((6, BLOCK), dtype=np.float64)
    for first in range(_U(start), _U(stop), _U(BLOCK)):
        count = min(_U(BLOCK), _U(stop) - first)
        _load(src, _U(src_stride), _U(c_in), first, count, buf)
        _apply_frame(buf, count, code)
        _store(buf, _U(c_out), first, count, dst, _U(dst_stride))


@njit(**_KERNEL)
def _normal_kernel(src, src_stride, dst, dst_stride, n, code, nchunks, workers, taken):
    for _worker in prange(workers):
        chunk = next_chunk(taken)
        while chunk < nchunks:
            start, stop = _chunk_bounds(chunk, n, nchunks)
            _normal_chunk(src, src_stride, dst, dst_stride, start, stop, code)
            chunk = next_chunk(taken)


@njit(**_KERNEL)
def _frame_kernel(src, src_stride, dst, dst_stride, n, code, c_in, c_out, nchunks, workers, taken):
    for _worker in prange(workers):
        chunk = next_chunk(taken)
        while chunk < nchunks:
            start, stop = _chunk_bounds(chunk, n, nchunks)
            _frame_chunk(src, src_stride, dst, dst_stride, start, stop, code, c_in, c_out)
            chunk = next_chunk(taken)


# ---------------------------------------------------------------------------
# Python side: strided (..., C) arrays as flat float32 buffers + row stride


def chunks(texels: int) -> tuple[int, int, np.ndarray]:
    """How a kernel splits ``texels`` work items: ``(chunks, workers, counter)``, the
    last three arguments of every parallel kernel here. Chunks go to whichever
    worker asks next (:mod:`matshop.parallel_chunks`), so a thread whose core is
    busy with something else takes fewer: several per thread, none tiny."""
    threads = get_num_threads()
    count = max(1, min(_CHUNKS_PER_THREAD * threads, texels // _MIN_CHUNK))
    return count, min(threads, count), np.zeros(1, dtype=np.int64)


@njit(**_INLINE)
def _chunk_bounds(chunk, n, nchunks):
    """The items ``[start, stop)`` of chunk ``chunk`` of ``nchunks`` over ``n``."""
    return chunk * n // nchunks, (chunk + 1) * n // nchunks


#: a strided array with more channels than this goes through packed copies
#: (the kernels keep one scratch row of BLOCK float64 per channel)
_MAX_STRIDED_CHANNELS = 8


def _flat_rows(rows: np.ndarray, writeable: bool) -> tuple[np.ndarray, int] | None:
    """Float32 ``(N, C)`` rows as (flat 1-D view over their memory, row stride in items).

    ``None`` when the rows cannot be addressed that way (channels not adjacent,
    negative or unaligned strides, too many channels): the caller goes
    through a packed copy. Read views are always read-only and write views
    always writeable, so each kernel compiles once.
    """
    count, channels = rows.shape
    item = rows.itemsize
    row_stride, channel_stride = rows.strides
    if count <= 1:
        row_stride = channels * item
    packed = row_stride == channels * item and (channels == 1 or channel_stride == item)
    strided_ok = channels <= _MAX_STRIDED_CHANNELS and (channels == 1 or channel_stride == item)
    if not (packed or strided_ok) or row_stride < 0 or row_stride % item:
        return None
    stride = row_stride // item
    span = (count - 1) * stride + channels if count else 0
    return as_strided(rows, shape=(span,), strides=(item,), writeable=writeable), stride


def _as_rows(array: np.ndarray) -> np.ndarray:
    """``(..., C)`` as ``(N, C)``: a view whenever numpy can make one (``()`` is one texel)."""
    if array.ndim == 2:
        return array
    return array.reshape(-1, array.shape[-1] if array.ndim else 1)


def _launch(src: np.ndarray, dst: np.ndarray, call) -> np.ndarray:
    """``call(src_flat, src_stride, dst_flat, dst_stride, texels)`` over float32 arrays.

    ``src`` (..., C_in) and ``dst`` (..., C_out) have the same leading shape;
    ``dst`` is written in place (through a packed temporary only when its
    layout cannot be addressed as strided rows) and returned.
    """
    if src.dtype != np.float32 or dst.dtype != np.float32:
        raise TypeError(f"kernels take float32 arrays, got {src.dtype} -> {dst.dtype}")
    if not dst.flags.writeable:
        raise ValueError("output array is read-only")
    src_rows = _as_rows(src)
    flat_src = _flat_rows(src_rows, False)
    if flat_src is None:
        flat_src = _flat_rows(np.ascontiguousarray(src_rows), False)
    dst_rows = _as_rows(dst)
    # reshape copies when the leading axes cannot be merged: then write through a temporary
    direct = dst.size == 0 or np.may_share_memory(dst_rows, dst)
    flat_dst = _flat_rows(dst_rows, True) if direct else None
    if flat_dst is None:
        packed = np.empty(dst_rows.shape, dtype=np.float32)
        call(*flat_src, *_flat_rows(packed, True), packed.shape[0])
        dst[...] = packed.reshape(dst.shape)
        return dst
    call(*flat_src, *flat_dst, dst_rows.shape[0])
    return dst


def transfer(
    src: np.ndarray,
    dst: np.ndarray,
    curve: int,
    lo: float = -_INF,
    hi: float = _INF,
    p: float = 1.0,
) -> np.ndarray:
    """``dst = curve(clamp(src, lo, hi))`` for every value; returns ``dst``.

    ``src`` and ``dst`` are float32 arrays of the same shape (any shape; the
    last axis counts as channels); ``dst`` may be a strided view (e.g. some
    channels of a wider array) and is written in place. ``p`` is the exponent
    of ``POWER``.
    """
    if src.shape != dst.shape:
        raise ValueError(f"transfer: shapes differ, {src.shape} -> {dst.shape}")
    args = (int(curve), float(lo), float(hi), float(p))
    if src.flags.c_contiguous and dst.flags.c_contiguous:
        # every value on its own: one long packed row
        _launch(src.reshape(-1, 1), dst.reshape(-1, 1), partial(_call_transfer, 1, args))
    elif src.shape[-1] > _MAX_STRIDED_CHANNELS:
        packed = np.empty(src.shape, dtype=np.float32)
        transfer(np.ascontiguousarray(src), packed, *args)
        dst[...] = packed
    else:
        _launch(src, dst, partial(_call_transfer, src.shape[-1], args))
    return dst


def _call_transfer(channels, args, src, src_stride, dst, dst_stride, n):
    _transfer_kernel(src, src_stride, dst, dst_stride, n, channels, *args, *chunks(n * channels))


def frames(src: np.ndarray, dst: np.ndarray, code: int) -> np.ndarray:
    """Frame conversion ``code`` (``NORMAL_TO_EDIT``, ...) of ``src`` into ``dst``; returns it.

    Float32 ``src`` (..., C_in) and ``dst`` (..., C_out) with the channel
    counts of ``FRAME_CHANNELS[code]``; ``dst`` may be a strided view.
    """
    c_in, c_out = FRAME_CHANNELS[code]
    if src.shape[:-1] != dst.shape[:-1] or src.shape[-1] != c_in or dst.shape[-1] != c_out:
        raise ValueError(
            f"frames: expected (..., {c_in}) -> (..., {c_out}), got {src.shape} -> {dst.shape}"
        )
    _launch(src, dst, partial(_call_frames, code, c_in, c_out))
    return dst


def _call_frames(code, c_in, c_out, src, src_stride, dst, dst_stride, n):
    if code in (NORMAL_TO_EDIT, NORMAL_FROM_EDIT):
        _normal_kernel(src, src_stride, dst, dst_stride, n, code, *chunks(n))
    else:
        _frame_kernel(src, src_stride, dst, dst_stride, n, code, c_in, c_out, *chunks(n))


# ---------------------------------------------------------------------------
# several conversions in one pass (a whole material)


@dataclass(frozen=True)
class Step:
    """One conversion a fused kernel runs: a :func:`transfer` curve or a :func:`frames` code."""

    #: False: ``transfer(src, dst, code, lo, hi, p)``; True: ``frames(src, dst, code)``
    frame: bool
    code: int
    lo: float = -_INF
    hi: float = _INF
    p: float = 1.0

    def run(self, src: np.ndarray, dst: np.ndarray) -> np.ndarray:
        """This conversion alone, ``src`` into ``dst`` (its own parallel pass)."""
        if self.frame:
            return frames(src, dst, self.code)
        return transfer(src, dst, self.code, self.lo, self.hi, self.p)

    def channels(self, c_in: int) -> tuple[int, int]:
        """Channels read and written for ``c_in`` input channels."""
        return FRAME_CHANNELS[self.code] if self.frame else (c_in, c_in)


#: conversions per pass of :func:`run_steps` (a fixed tuple length: one compilation)
_MAX_STEPS = 8


@njit(**_WORKER)
def _steps_chunk(srcs, src_strides, dsts, dst_strides, table, coeffs, count_steps, start, stop):
    buf = np.empty((_MAX_STRIDED_CHANNELS, BLOCK), dtype=np.float64)
    for first in range(_U(start), _U(stop), _U(BLOCK)):
        count = min(_U(BLOCK), _U(stop) - first)
        for s in range(count_steps):
            frame, code, c_in, c_out = table[s, 0], table[s, 1], _U(table[s, 2]), _U(table[s, 3])
            _load(srcs[s], _U(src_strides[s]), c_in, first, count, buf)
            if frame == 0:
                _apply_curve(buf, c_in, count, code, coeffs[s, 0], coeffs[s, 1], coeffs[s, 2])
            elif code == NORMAL_TO_EDIT or code == NORMAL_FROM_EDIT:
                _apply_normal(buf, count, code)
            else:
                _apply_frame(buf, count, code)
            _store(buf, c_out, first, count, dsts[s], _U(dst_strides[s]))


@njit(**_KERNEL)
def _steps_kernel(
    srcs, src_strides, dsts, dst_strides, table, coeffs, count_steps, n, nchunks, workers, taken
):
    for _worker in prange(workers):
        chunk = next_chunk(taken)
        while chunk < nchunks:
            start, stop = _chunk_bounds(chunk, n, nchunks)
            _steps_chunk(
                srcs, src_strides, dsts, dst_strides, table, coeffs, count_steps, start, stop
            )
            chunk = next_chunk(taken)


def run_steps(jobs: list[tuple[Step, np.ndarray, np.ndarray]]) -> None:
    """Run every ``(step, src, dst)`` in one parallel pass over their texels.

    All ``src`` (..., C_in) and ``dst`` (..., C_out) float32 arrays share their
    leading shape; ``dst`` is written in place and may be a strided view (some
    channels of a material's edit array). A block of texels goes through every
    step while it is in cache: a material's maps are read and its edit array
    written once, instead of once per parameter, and the page faults of a new
    output are taken by all threads. Jobs that cannot be addressed as strided
    rows (more than 8 channels, non-mergeable views) run alone.
    """
    fused = []
    for step, src, dst in jobs:
        c_in, c_out = step.channels(src.shape[-1])
        src_rows, dst_rows = _as_rows(src), _as_rows(dst)
        flat_src = _flat_rows(src_rows, False) if src.dtype == np.float32 else None
        direct = dst.dtype == np.float32 and np.may_share_memory(dst_rows, dst)
        flat_dst = _flat_rows(dst_rows, True) if direct and dst.flags.writeable else None
        shapes_ok = src.shape[:-1] == dst.shape[:-1] and (src.shape[-1], dst.shape[-1]) == (
            c_in,
            c_out,
        )
        small = max(c_in, c_out) <= _MAX_STRIDED_CHANNELS and src_rows.shape[0] > 1
        if flat_src is None or flat_dst is None or not (shapes_ok and small):
            step.run(src, dst)
            continue
        fused.append((step, c_in, c_out, flat_src, flat_dst))
    if not fused:
        return
    n = _as_rows(jobs[0][1]).shape[0]
    for first in range(0, len(fused), _MAX_STEPS):
        group = fused[first : first + _MAX_STEPS]
        # pad to a fixed length so every material uses the same compiled kernel
        pad = [group[0]] * (_MAX_STEPS - len(group))
        table = np.array(
            [(int(s.frame), s.code, c_in, c_out) for s, c_in, c_out, _, _ in group + pad],
            dtype=np.int64,
        )
        coeffs = np.array([(s.lo, s.hi, s.p) for s, *_ in group + pad], dtype=np.float64)
        srcs = tuple(f[3][0] for f in group + pad)
        dsts = tuple(f[4][0] for f in group + pad)
        src_strides = np.array([f[3][1] for f in group + pad], dtype=np.int64)
        dst_strides = np.array([f[4][1] for f in group + pad], dtype=np.int64)
        _steps_kernel(
            srcs, src_strides, dsts, dst_strides, table, coeffs, len(group), n, *chunks(n * 4)
        )


@njit(cache=True, parallel=True, nogil=True)
def normalize_or_z(v, tiny, out):
    """Rows of ``v`` (n, 3) float32 scaled to unit length into ``out``; length <= ``tiny`` (or NaN)
    gives ``+z``. The float32 operations and their order are numpy's
    (``sqrt((x*x + y*y) + z*z)``, then a division), so the result is the same bits."""
    for i in prange(v.shape[0]):
        x, y, z = v[i, 0], v[i, 1], v[i, 2]
        length = np.sqrt(x * x + y * y + z * z)
        if length > tiny:
            out[i, 0], out[i, 1], out[i, 2] = x / length, y / length, z / length
        else:
            out[i, 0], out[i, 1], out[i, 2] = 0.0, 0.0, 1.0


@njit(cache=True, parallel=True, nogil=True)
def decode_normals(rgb, sign_y, tiny, out):
    """Normal-map pixels ``rgb`` (n, 3) float32 in [0, 1] -> unit normals into ``out``:
    ``n = 2 rgb - 1``, green times ``sign_y`` (-1 flips DirectX's), then as
    :func:`normalize_or_z`. One pass where numpy made three arrays; each float32
    operation is numpy's, in numpy's order, so the result is the same bits."""
    two, one = np.float32(2.0), np.float32(1.0)
    for i in prange(rgb.shape[0]):
        x = two * rgb[i, 0] - one
        y = sign_y * (two * rgb[i, 1] - one)
        z = two * rgb[i, 2] - one
        length = np.sqrt(x * x + y * y + z * z)
        if length > tiny:
            out[i, 0], out[i, 1], out[i, 2] = x / length, y / length, z / length
        else:
            out[i, 0], out[i, 1], out[i, 2] = 0.0, 0.0, 1.0


@njit(inline="always", nogil=True)
def _unit_clip(v):
    # comparisons, not min/max: NaN fails both and passes through, as in np.clip
    if v < 0.0:
        return np.float32(0.0)
    if v > 1.0:
        return np.float32(1.0)
    return v


@njit(cache=True, parallel=True, nogil=True)
def encode_normals(n, sign_y, tiny, out):
    """Normals ``n`` (n, 3) float32 -> file pixels into ``out``: as :func:`normalize_or_z`,
    green times ``sign_y``, then ``clip(0.5 n + 0.5, 0, 1)`` (NaN stays NaN, as with
    ``np.clip``). One pass where numpy made five arrays; the same bits as numpy."""
    half = np.float32(0.5)
    for i in prange(n.shape[0]):
        x, y, z = n[i, 0], n[i, 1], n[i, 2]
        length = np.sqrt(x * x + y * y + z * z)
        if length > tiny:
            x, y, z = x / length, y / length, z / length
        else:
            x, y, z = np.float32(0.0), np.float32(0.0), np.float32(1.0)
        y = sign_y * y
        out[i, 0] = _unit_clip(half * x + half)
        out[i, 1] = _unit_clip(half * y + half)
        out[i, 2] = _unit_clip(half * z + half)
