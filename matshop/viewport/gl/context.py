"""Getting an OpenGL 3.3+ core context: the default format, and an offscreen one.

Qt decides a QOpenGLWidget's format from ``QSurfaceFormat.defaultFormat()``
*when the QApplication is created*, so :func:`install_default_format` must run
before that (tests call it at import time; the app calls it in ``main``).
:class:`OffscreenContext` is a context with no window, for tests, benchmarks
and scripts that only need images.
"""

from __future__ import annotations

import os

from PySide6.QtGui import QOffscreenSurface, QOpenGLContext, QSurfaceFormat

#: the oldest version whose core profile has everything the shaders use
MIN_VERSION = (3, 3)


class GLUnavailable(RuntimeError):
    """No OpenGL 3.3+ core context can be created here (no display, no driver)."""


def surface_format() -> QSurfaceFormat:
    """Core profile, 3.3 or later, with a depth buffer."""
    fmt = QSurfaceFormat()
    fmt.setRenderableType(QSurfaceFormat.RenderableType.OpenGL)
    fmt.setVersion(*MIN_VERSION)
    fmt.setProfile(QSurfaceFormat.OpenGLContextProfile.CoreProfile)
    fmt.setDepthBufferSize(24)
    return fmt


def no_display_reason() -> str | None:
    """Why Qt would find no display for a GL context here (None: there is one to try).

    Checked before Qt starts: without a display, creating the QApplication
    aborts the whole process instead of raising.
    """
    platform = os.environ.get("QT_QPA_PLATFORM", "")
    if platform.startswith(("offscreen", "minimal")):
        return None  # Qt starts; context creation then fails cleanly
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    return "no display for an OpenGL context: run under xvfb-run"


def install_default_format() -> None:
    """Make :func:`surface_format` the default (call before the QApplication exists)."""
    QSurfaceFormat.setDefaultFormat(surface_format())


def check_version(context: QOpenGLContext) -> None:
    got = context.format()
    version = (got.majorVersion(), got.minorVersion())
    if version < MIN_VERSION:
        raise GLUnavailable(
            f"OpenGL {version[0]}.{version[1]} context; the viewport needs "
            f"{MIN_VERSION[0]}.{MIN_VERSION[1]} core"
        )


class OffscreenContext:
    """A current-able OpenGL context on an offscreen surface (needs a QGuiApplication)."""

    def __init__(self) -> None:
        from PySide6.QtGui import QGuiApplication

        if QGuiApplication.instance() is None:
            raise GLUnavailable("no QGuiApplication: create one before an OpenGL context")
        self.context = QOpenGLContext()
        self.context.setFormat(surface_format())
        if not self.context.create():
            raise GLUnavailable("QOpenGLContext.create() failed (no OpenGL driver or display)")
        check_version(self.context)
        self.surface = QOffscreenSurface()
        self.surface.setFormat(self.context.format())
        self.surface.create()
        if not self.surface.isValid() or not self.make_current():
            raise GLUnavailable("cannot make an offscreen OpenGL context current")

    def make_current(self) -> bool:
        return bool(self.context.makeCurrent(self.surface))

    def done_current(self) -> None:
        self.context.doneCurrent()


def renderer_string() -> str:
    """``GL_RENDERER`` and ``GL_VERSION`` of the current context (llvmpipe, a GPU ...)."""
    from OpenGL import GL

    renderer = GL.glGetString(GL.GL_RENDERER) or b"?"
    version = GL.glGetString(GL.GL_VERSION) or b"?"
    return f"{renderer.decode()} / OpenGL {version.decode()}"
