"""Chunks of a parallel loop, handed to whichever thread asks next.

numba splits a ``prange`` evenly between its threads before they start (its
OpenMP layer schedules statically), so the loop lasts as long as its slowest
thread. On a shared machine a core is often busy with something else for a
few milliseconds; the thread on it falls behind and the other, done with its
half, waits. A kernel that runs ``prange(workers)`` with one worker per
thread, each taking chunk after chunk from a shared counter
(:func:`next_chunk`) until none is left, keeps every thread at work to the
end. Measured on levels' kernel at 2K x 10 channels, two threads, 40 calls
each: about the same on a quiet machine (median 35.5 against 36.2 ms), 38.8
against 44.7 ms while another process kept one core a fifth busy.
"""

from __future__ import annotations

from numba import types
from numba.extending import intrinsic


@intrinsic
def next_chunk(typingctx, counter):
    """``counter[0]``, and 1 added to it, as one atomic step (``counter``: an int64
    array shared by the workers); the caller's next chunk, or one past the last.

    Pass the counter into the kernel rather than make it there: numba's parallel
    transforms do not see this call write it, and a kernel that made it with
    ``np.zeros`` read back the zero after its loop.
    """
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None

    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        one = context.get_constant(types.int64, 1)
        # "monotonic": only the count is shared; the chunks' writes do not overlap,
        # and the end of the parallel loop orders them before the caller reads
        return builder.atomic_rmw("add", array.data, one, "monotonic")

    return types.int64(counter), codegen
