"""A new environment goes up to the 3D view a band a frame, not in one stall.

An artist's HDR is large (a 4K equirect and its mip chain are 133 MB of float32;
sent in one call from the GUI thread it stalled the editor 238 ms here, an 8K
one four times that). The view now allocates each level and sends bands of rows
over the next frames while it keeps drawing the previous environment
(``MaterialRenderer.set_environment(..., incremental=True)``). These tests drive
the real widget under the event loop and read the textures back: every texel of
every mip level and of the irradiance map is the environment's own, bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from gl_testing import shown_viewport  # noqa: E402
from OpenGL import GL  # noqa: E402

from matshop.render.environment import Environment  # noqa: E402
from matshop.viewport.gl import renderer as renderer_module  # noqa: E402

#: a step small enough that the test's environment takes many frames
STEP_BYTES = 64 << 10


def hdr(rows: int, seed: int) -> Environment:
    """An equirect with a sun 400 times the sky, as the sky preset has."""
    rng = np.random.default_rng(seed)
    radiance = rng.random((rows, 2 * rows, 3), dtype=np.float32)
    radiance[rows // 4, rows // 3] = 400.0
    return Environment(radiance, name=f"hdr {seed}")


def read_level(texture: int, unit: int, level: int) -> np.ndarray:
    GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
    GL.glBindTexture(GL.GL_TEXTURE_2D, texture)
    GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
    width = GL.glGetTexLevelParameteriv(GL.GL_TEXTURE_2D, level, GL.GL_TEXTURE_WIDTH)
    height = GL.glGetTexLevelParameteriv(GL.GL_TEXTURE_2D, level, GL.GL_TEXTURE_HEIGHT)
    data = GL.glGetTexImage(GL.GL_TEXTURE_2D, level, GL.GL_RGB, GL.GL_FLOAT)
    return np.frombuffer(data, dtype=np.float32).reshape(height, width, 3)


def assert_on_the_gpu(viewport, environment: Environment) -> None:
    """Every level the view samples holds the environment's texels."""
    viewport.makeCurrent()
    try:
        textures = viewport.renderer.environment
        assert textures.env is environment
        for level, image in enumerate(environment.levels):
            got = read_level(textures.radiance, textures.RADIANCE_UNIT, level)
            assert np.array_equal(got, image), f"radiance level {level}"
        got = read_level(textures.irradiance, textures.IRRADIANCE_UNIT, 0)
        assert np.array_equal(got, environment.irradiance_map)
    finally:
        viewport.doneCurrent()


@pytest.fixture
def small_steps(monkeypatch):
    monkeypatch.setattr(renderer_module, "STEP_BYTES", STEP_BYTES)


def test_the_environment_goes_up_over_frames_and_lands_texel_for_texel(
    gl_context, qtbot, small_steps, monkeypatch
) -> None:
    viewport = shown_viewport(qtbot, 48)
    viewport.render_image(8)  # the renderer exists, with its first environment
    first = viewport.renderer.environment.env
    environment = hdr(128, seed=1)
    uploads = []
    real_upload = type(viewport.renderer.environment).upload

    def counted(textures, budget_bytes):
        uploads.append(budget_bytes)
        return real_upload(textures, budget_bytes)

    monkeypatch.setattr(type(viewport.renderer.environment), "upload", counted)
    viewport.set_environment(environment)
    # nothing sent yet: the previous environment is still the one drawn
    assert viewport.renderer.environment.env is first
    assert viewport.renderer.loading
    qtbot.waitUntil(lambda: not viewport.renderer.loading, timeout=10_000)
    level_bytes = sum(image.nbytes for image in environment.levels)
    assert len(uploads) >= level_bytes // STEP_BYTES // 2  # one band a frame, many frames
    assert all(budget == STEP_BYTES for budget in uploads)
    assert_on_the_gpu(viewport, environment)


def test_a_newer_environment_replaces_one_still_on_its_way(gl_context, qtbot, small_steps):
    viewport = shown_viewport(qtbot, 48)
    viewport.render_image(8)
    superseded, wanted = hdr(64, seed=2), hdr(96, seed=3)
    viewport.set_environment(superseded)
    viewport.renderer.sync()  # one band of the first one goes up
    pending = viewport.renderer._next_environment
    assert pending is not None and pending.env is superseded
    names = (pending.radiance, pending.irradiance)
    viewport.set_environment(wanted)
    qtbot.waitUntil(lambda: not viewport.renderer.loading, timeout=10_000)
    assert_on_the_gpu(viewport, wanted)
    viewport.makeCurrent()
    try:  # the superseded textures were deleted, not leaked
        assert not any(GL.glIsTexture(name) for name in names)
    finally:
        viewport.doneCurrent()


def test_an_image_of_the_view_waits_for_the_whole_environment(gl_context, qtbot, small_steps):
    """``render_image`` (thumbnails, exports of the view) shows the environment asked for,
    all of it: the same pixels as a view that had it from the start."""
    environment = hdr(64, seed=4)
    reference_view = shown_viewport(qtbot, 48)
    reference_view.set_environment(environment)  # before the renderer exists: at once
    expected = reference_view.render_image(40)
    viewport = shown_viewport(qtbot, 48)
    viewport.render_image(8)
    viewport.set_environment(environment)
    assert viewport.renderer.loading
    got = viewport.render_image(40)
    assert not viewport.renderer.loading
    assert np.array_equal(got, expected)
    assert_on_the_gpu(viewport, environment)


def test_going_back_to_the_environment_drawn_drops_the_one_on_its_way(
    gl_context, qtbot, small_steps
) -> None:
    """Choosing another environment and then the one shown again (a quick change of
    mind in the lighting menu) sends nothing more: the drawn textures stay, the
    half-sent ones are deleted."""
    viewport = shown_viewport(qtbot, 48)
    shown = hdr(64, seed=5)
    viewport.set_environment(shown)
    qtbot.waitUntil(lambda: not viewport.renderer.loading, timeout=10_000)
    drawn = viewport.renderer.environment
    viewport.set_environment(hdr(96, seed=6))
    viewport.renderer.sync()
    pending = viewport.renderer._next_environment
    names = (pending.radiance, pending.irradiance)
    viewport.set_environment(shown)
    assert not viewport.renderer.loading
    assert viewport.renderer.environment is drawn  # the same textures, not sent again
    viewport.makeCurrent()
    try:
        assert not any(GL.glIsTexture(name) for name in names)
    finally:
        viewport.doneCurrent()
    assert_on_the_gpu(viewport, shown)
