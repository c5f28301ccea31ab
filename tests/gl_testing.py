"""What the OpenGL test modules share (their ``gl_context`` fixture is in conftest.py):
:func:`require_gl`, called at the top of each, and a shown viewport.
"""

from __future__ import annotations

import pytest


def require_gl() -> None:
    """Skip the calling module, with the reason, unless PySide6's OpenGL widgets, PyOpenGL,
    pytest-qt and an OpenGL 3.3 core context are all there; else set the default surface
    format, which must happen before pytest-qt creates the QApplication."""
    pytest.importorskip("PySide6.QtOpenGLWidgets", reason="PySide6 (extra 'gui') not installed")
    pytest.importorskip("OpenGL.GL", reason="PyOpenGL (extra 'gui') not installed")
    pytest.importorskip("pytestqt", reason="pytest-qt (extra 'test') not installed")
    from matshop.viewport.gl.context import install_default_format, no_display_reason

    install_default_format()
    reason = no_display_reason()
    if reason is not None:
        pytest.skip(reason, allow_module_level=True)


def shown_viewport(qtbot, size: int, widget_class=None):
    """A :class:`MaterialViewport` (or ``widget_class``, a subclass) of ``size`` x ``size``,
    shown and exposed."""
    from matshop.viewport.gl.view import MaterialViewport

    widget = (widget_class or MaterialViewport)()
    widget.resize(size, size)
    qtbot.addWidget(widget)
    widget.show()
    qtbot.waitExposed(widget)
    return widget


def release(widget) -> None:
    """Drop the widget's document and its GPU textures now: Qt deletes a closed widget
    late, and a 512^2 sampled lobe holds about 1 GB until then."""
    widget.set_document(None)
    widget.render_image(8)  # the frame applies it: the textures are deleted


def swatch_rows(shape: tuple[int, int], step: int):
    """Every ``step``-th image row of the lit display's swatch (tilted 30 degrees), shaded
    by ``render()`` exactly as in a whole render (same pixel footprint and prefilter level)."""
    import numpy as np

    from matshop.render import scenes

    whole = scenes.swatch(shape, tilt_deg=30.0)
    keep = np.zeros(shape, dtype=bool)
    keep[::step] = True
    flat = keep.reshape(-1)
    return scenes.GBuffer(
        mask=keep,
        uv=whole.uv[flat],
        normal=whole.normal[flat],
        tangent=whole.tangent[flat],
        bitangent=whole.bitangent[flat],
        view=whole.view[flat],
        uv_per_pixel=whole.uv_per_pixel,
    )
