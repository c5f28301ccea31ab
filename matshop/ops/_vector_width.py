"""512-bit vectors for one numba kernel, where the CPU has them.

LLVM tunes code for the AVX-512 Intel CPUs (Skylake-SP onwards) to prefer
256-bit vectors, to keep their clocks up under mixed work; numba follows, and
its only way around that is process-wide (``NUMBA_CPU_FEATURES``), which
changes every kernel and every cache key. A kernel bound by arithmetic on
values streamed once (levels' power: 48 -> 36 ms at 2K x 10 channels, one
call on two threads) gains from twice the lanes, so such a kernel asks for
them itself: :func:`prefer_512_bit_vectors`, called in its body, sets the LLVM
attribute ``"prefer-vector-width"="512"`` on the function being compiled,
which LLVM reads when it picks that function's vector width. Where the CPU
has no 512-bit registers the attribute changes nothing. A kernel bound by
loads and stores gains nothing (measured: the separable bilateral), so it is
used only where a benchmark showed a gain.
"""

from __future__ import annotations

from numba import types
from numba.extending import intrinsic

#: the LLVM function attribute (a string attribute: key and value quoted)
PREFER_512 = '"prefer-vector-width"="512"'


@intrinsic
def prefer_512_bit_vectors(typingctx):
    """Call first in an ``@njit`` function: its loops may use 512-bit vectors (no value)."""

    def codegen(context, builder, signature, args):
        # llvmlite checks attribute names against a fixed list that has no
        # key="value" attributes; the set underneath takes any string
        set.add(builder.function.attributes, PREFER_512)
        return context.get_dummy_value()

    return types.none(), codegen
