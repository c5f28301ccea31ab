"""The speed estimate that sizes work drawn in bands within a time budget (the 3D view's
frames, :mod:`.gl.banded_frame`; the lit display's passes, :mod:`matshop.app.lit_gl`).

Qt- and OpenGL-free, so the lit display's worker can import it before OpenGL is known to work.
"""

from __future__ import annotations


def follow_speed(previous: float | None, measured: float) -> float:
    """The next estimate of seconds per unit of work (a row, a pixel) after a band took
    ``measured``: a slowdown counts at once, since the next band must keep to its budget;
    a speed-up through a running mean that forgets in a few bands (the machine's load
    changes). ``previous`` None: nothing was measured before."""
    if previous is None:
        return measured
    return max(measured, 0.7 * previous + 0.3 * measured)
