"""A view's frames drawn in row bands that each keep to a time budget.

On a GPU a frame of the 3D view takes a millisecond and is drawn whole. Software
OpenGL (Mesa's llvmpipe, what CI and machines without a GPU have) takes 0.1-0.5 s
for the same frame, and the window waits for it when it composes the widget, so
one frame would stall the event loop for as long. :class:`BandedFrames` draws such
a frame in bands of rows over several paints, each band sized by the speed the
previous band measured, into a back buffer; the front buffer holds the last whole
frame and is what the widget shows meanwhile, so the picture never tears. A frame
that fits the budget is one band: the only cost is one copy. A resized view shows
its last whole frame stretched until the first frame of its new size is whole.

A change while a frame is being drawn does not restart it (a drag's stream of
changes would starve the view): the frame finishes, with the state it began with,
and the next one starts at once.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from OpenGL import GL

from ..band_speed import follow_speed
from .fbo import Framebuffer

#: rows of the first band when nothing was measured yet (a new view)
PROBE_ROWS = 32


class BandedFrames:
    """Front and back buffers of one view and the frame being drawn (see the module doc)."""

    def __init__(self, budget_s: float) -> None:
        self.budget_s = budget_s
        self.s_per_row: float | None = None
        self._front: Framebuffer | None = None  # the last whole frame (of any size)
        self._back: Framebuffer | None = None  # the frame under way (of the view's size)
        self._next_row: int | None = 0  # the back buffer's next band (None: no frame under way)
        self._requested = False  # a change came while a frame was under way

    @property
    def drawing(self) -> bool:
        """A frame is under way or due: paint again to draw its next band."""
        return self._next_row is not None or self._requested

    def request(self) -> None:
        """The picture changed: a new frame, now or once the one under way is whole."""
        if self._next_row is None:
            self._next_row = 0
        else:
            self._requested = True

    def paint(
        self,
        target: int,
        width: int,
        height: int,
        begin: Callable[[], None],
        draw: Callable[[], None],
        *,
        whole: bool = False,
    ) -> None:
        """Draw the next band with ``draw`` (which draws a whole ``width x height`` frame into
        the bound framebuffer; the scissor keeps the band) and show the last whole frame in
        framebuffer ``target``. ``begin`` is called before a frame's first band (to fix the
        state the frame shows). ``whole``: draw the rest of the frame, and the one due after
        it, now (a grab)."""
        if self._back is None or (self._back.width, self._back.height) != (width, height):
            if self._back is not None:  # resized: the old whole frame is shown stretched
                self._back.delete()
            self._back = Framebuffer(width, height)
            self._next_row, self._requested = 0, False
        while True:
            if self._next_row is None and self._requested:
                self._next_row, self._requested = 0, False
            if self._next_row is None:
                break
            if self._next_row == 0:
                begin()
            self._draw_band(width, height, draw, whole)
            if not whole:
                break
        GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, target)
        GL.glViewport(0, 0, width, height)
        front = self._front
        if front is None:  # nothing whole yet: the background colour, not a torn frame
            GL.glClearColor(0.0, 0.0, 0.0, 1.0)
            GL.glClear(GL.GL_COLOR_BUFFER_BIT)
            return
        same = (front.width, front.height) == (width, height)
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, front.id)
        GL.glBlitFramebuffer(
            0,
            0,
            front.width,
            front.height,
            0,
            0,
            width,
            height,
            GL.GL_COLOR_BUFFER_BIT,
            GL.GL_NEAREST if same else GL.GL_LINEAR,
        )
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, target)

    def _draw_band(self, width: int, height: int, draw: Callable[[], None], whole: bool) -> None:
        top = self._next_row
        if whole:
            rows = height - top
        elif self.s_per_row is None:
            rows = PROBE_ROWS
        else:
            rows = max(1, int(self.budget_s / self.s_per_row))
        bottom = min(height, top + rows)
        self._back.bind()
        GL.glEnable(GL.GL_SCISSOR_TEST)
        GL.glScissor(0, height - bottom, width, bottom - top)  # GL counts rows from the bottom
        began = time.perf_counter()
        try:
            draw()
            GL.glFinish()  # the band's real cost, and the window does not wait for it later
        finally:
            GL.glDisable(GL.GL_SCISSOR_TEST)
        self.s_per_row = follow_speed(
            self.s_per_row, (time.perf_counter() - began) / (bottom - top)
        )
        if bottom < height:
            self._next_row = bottom
            return
        old_front, self._front, self._next_row = self._front, self._back, None
        if old_front is not None and (old_front.width, old_front.height) == (width, height):
            self._back = old_front  # the next frame is drawn into it
        else:
            if old_front is not None:
                old_front.delete()
            self._back = Framebuffer(width, height)

    def delete(self) -> None:
        """Free the buffers (a current context needed)."""
        for buffer in (self._front, self._back):
            if buffer is not None:
                buffer.delete()
        self._front = self._back = None
