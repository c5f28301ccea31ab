"""The per-kernel 512-bit request reaches LLVM: the same loop, with and without it.

Truth is the machine code LLVM emits for two twins of one float32 loop
(compiled here, uncached, so they can be inspected): the twin that asks
uses 512-bit (zmm) registers on a CPU with AVX-512 (the other does not on
this machine's Intel CPU: measured, not asserted, since an AMD CPU's tuning
may prefer them anyway); both compute the same values as numpy.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from matshop.ops._vector_width import PREFER_512, prefer_512_bit_vectors


def _cpu_has_avx512f() -> bool:
    try:
        with open("/proc/cpuinfo") as info:
            return " avx512f" in info.read()
    except OSError:
        return False


@njit(fastmath={"contract"}, error_model="numpy")
def _plain(values, out):
    for i in range(values.shape[0]):
        out[i] = np.sqrt(values[i]) * np.float32(1.5) + values[i]


@njit(fastmath={"contract"}, error_model="numpy")
def _wide(values, out):
    prefer_512_bit_vectors()
    for i in range(values.shape[0]):
        out[i] = np.sqrt(values[i]) * np.float32(1.5) + values[i]


def _compiled():
    values = np.linspace(0.0, 4.0, 1000, dtype=np.float32)
    outs = [np.empty_like(values), np.empty_like(values)]
    _plain(values, outs[0])
    _wide(values, outs[1])
    return values, outs


def test_both_twins_compute_the_numpy_values() -> None:
    values, (plain, wide) = _compiled()
    expected = (np.sqrt(values.astype(np.float64)) * 1.5 + values).astype(np.float32)
    np.testing.assert_allclose(plain, expected, rtol=2e-7)
    np.testing.assert_array_equal(wide, plain)


def test_the_attribute_is_on_the_asking_function_only() -> None:
    _compiled()
    assert PREFER_512 in _wide.inspect_llvm(_wide.signatures[0])
    assert PREFER_512 not in _plain.inspect_llvm(_plain.signatures[0])


@pytest.mark.skipif(not _cpu_has_avx512f(), reason="the CPU has no 512-bit vectors")
def test_llvm_emits_512_bit_vectors_where_asked() -> None:
    """(Whether the plain twin uses them is the CPU's tuning: not on Intel's, by default.)"""
    _compiled()
    assert "zmm" in _wide.inspect_asm(_wide.signatures[0])
