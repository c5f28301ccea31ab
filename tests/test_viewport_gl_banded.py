"""A frame too slow for one paint is drawn in bands over several paints
(``viewport.gl.banded_frame``), and nothing of that shows: every paint leaves the last
whole picture in the widget's framebuffer (never a frame half old, half new), and the
finished frame is, pixel for pixel, the frame drawn whole in one go offscreen
(``render_image``). A change while a frame is drawn (a drag going on) does not restart
it: that frame is finished with the view it began with, then the latest view is drawn.
A grab waits for the whole frame.

Bands are forced here with a zero budget (one row a paint after the first band), so
the test does not depend on how fast this machine's OpenGL is. Run under
``xvfb-run -a``; skips, saying why, only without an OpenGL 3.3 context.
"""

from __future__ import annotations

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from gl_testing import release, shown_viewport  # noqa: E402
from OpenGL import GL  # noqa: E402
from test_viewport_gl_variance import bumpy_metal  # noqa: E402

from matshop.layers import Document  # noqa: E402
from matshop.viewport.gl.view import MaterialViewport  # noqa: E402

VIEW = 72


class Recording(MaterialViewport):
    """A viewport that keeps what each paint left in its framebuffer (RGB, top row first):
    what the window composes."""

    def __init__(self) -> None:
        super().__init__()
        self.shown: list[np.ndarray] = []

    def paintGL(self) -> None:  # noqa: N802 - Qt's name
        super().paintGL()
        width, height = self._pixel_size()
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self.defaultFramebufferObject())
        data = GL.glReadPixels(0, 0, width, height, GL.GL_RGBA, GL.GL_UNSIGNED_BYTE)
        pixels = np.frombuffer(data, np.uint8).reshape(height, width, 4)
        self.shown.append(pixels[::-1, :, :3].copy())


@pytest.fixture
def viewport(gl_context, qtbot):
    widget = shown_viewport(qtbot, VIEW, Recording)
    widget.set_document(Document.from_material(bumpy_metal(64)))
    widget.update()
    settle(widget, qtbot)
    yield widget
    release(widget)


def settle(widget, qtbot) -> None:
    qtbot.waitUntil(lambda: not widget.drawing and not widget.renderer.loading, timeout=60_000)


def whole(widget) -> np.ndarray:
    """The same view drawn whole in one go, offscreen (RGB)."""
    return widget.render_image((widget.width(), widget.height()))[..., :3]


def test_a_banded_frame_shows_the_old_picture_until_it_is_whole(viewport, qtbot) -> None:
    before = whole(viewport)
    assert np.array_equal(viewport.shown[-1], before)
    viewport.frames.budget_s = 0.0  # one row a paint after the first band
    viewport.camera.orbit(40.0, 15.0)
    painted = len(viewport.shown)
    viewport.update()
    settle(viewport, qtbot)
    after = whole(viewport)
    frames = viewport.shown[painted:]
    print(f"{len(frames)} paints for one frame of {VIEW} rows")
    assert np.abs(after.astype(int) - before.astype(int)).max() > 40  # the view did turn
    assert len(frames) >= VIEW // 2  # it was banded
    for index, frame in enumerate(frames[:-1]):
        assert np.array_equal(frame, before), f"paint {index} shows a torn frame"
    assert np.array_equal(frames[-1], after)


def test_a_grab_draws_the_rest_of_the_frame(viewport, qtbot) -> None:
    from PySide6.QtGui import QImage

    viewport.frames.budget_s = 0.0
    viewport.camera.orbit(-60.0, 0.0)
    viewport.update()
    viewport.repaint()  # one band drawn, the frame not whole yet
    assert viewport.drawing
    image = viewport.grabFramebuffer().convertToFormat(QImage.Format.Format_RGB888)
    rows = np.frombuffer(image.constBits(), np.uint8).reshape(VIEW, image.bytesPerLine())
    grabbed = rows[:, : 3 * VIEW].reshape(VIEW, VIEW, 3)
    assert not viewport.drawing
    assert np.array_equal(grabbed, whole(viewport))


def test_a_change_during_a_frame_is_drawn_by_the_next_one(viewport, qtbot) -> None:
    import copy

    before = whole(viewport)
    viewport.frames.budget_s = 0.0
    viewport.camera.orbit(35.0, 0.0)
    first_camera = copy.deepcopy(viewport.camera)
    viewport.update()
    painted = len(viewport.shown)
    viewport.repaint()  # the first band of the frame of the first turn
    viewport.camera.orbit(35.0, 0.0)  # a drag goes on while that frame is drawn
    viewport.update()
    settle(viewport, qtbot)
    second = whole(viewport)
    viewport.camera, live = first_camera, viewport.camera
    first = whole(viewport)
    viewport.camera = live
    frames = viewport.shown[painted:]
    kinds = [
        next((k for k, image in enumerate((before, first, second)) if np.array_equal(f, image)), -1)
        for f in frames
    ]
    counts = [kinds.count(k) for k in (0, 1, 2, -1)]
    print(f"{len(frames)} paints show old, first, second, other: {counts}")
    assert -1 not in kinds  # no paint shows a mix of two views
    assert kinds == sorted(kinds) and kinds[-1] == 2  # in order, ending on the latest view
    assert 1 in kinds  # the first turn's frame was finished and shown, not dropped


def test_a_resized_view_shows_its_last_frame_stretched_until_the_new_one_is_whole(
    viewport, qtbot
) -> None:
    import cv2

    before = whole(viewport)
    viewport.frames.budget_s = 0.0
    viewport.resize(VIEW + 40, VIEW)
    painted = len(viewport.shown)
    settle(viewport, qtbot)
    frames = viewport.shown[painted:]
    stretched = cv2.resize(before, (VIEW + 40, VIEW), interpolation=cv2.INTER_LINEAR)
    assert len(frames) > 2 and frames[0].shape == stretched.shape
    # the old picture, stretched (GL's and OpenCV's bilinear differ a little at the edges)
    assert np.abs(frames[0].astype(int) - stretched.astype(int)).mean() < 3.0
    assert np.array_equal(frames[-1], whole(viewport))
