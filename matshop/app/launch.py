"""Start the editor: what ``matshop open [PATH]`` and a bare ``matshop`` run."""

from __future__ import annotations

from pathlib import Path


def start(path: Path | None = None, argv: list[str] | None = None) -> int:
    """Run the editor until its window closes; returns the exit status."""
    import sys

    from PySide6.QtWidgets import QApplication

    from ..kernel_cache import cached_kernels_without_compiler_set_up
    from . import error_hook
    from .main_window import MainWindow
    from .theme import apply_theme

    app = QApplication.instance() or QApplication(argv if argv is not None else sys.argv[:1])
    app.setApplicationName("matshop")
    app.setOrganizationName("matshop")
    apply_theme(app)
    window = MainWindow()
    error_hook.install(window.show_message)
    # a kernel's first load on a worker holds the GIL, so the event loop waits for it
    with cached_kernels_without_compiler_set_up():
        window.show()
        # a cold numba cache (a fresh install): compile in a child, not on first use here
        window.kernel_warm_up.start_if_cold()
        if path is not None:
            window.open_path(path)
        return int(app.exec())
