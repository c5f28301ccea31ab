"""``matshop open [PATH]``: start the editor.

``add_parsers`` imports only the standard library (``matshop --help`` stays
fast and Qt-free); ``run`` imports Qt.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

VERB_MODULE = "matshop.app.verbs"


def add_parsers(verbs: Any) -> None:
    parser = verbs.add_parser(
        "open",
        help="start the editor (optionally opening a texture set or a .matshop project)",
        description="Start the matshop editor. PATH may be a texture set (a folder or one "
        "of its maps) or a .matshop project.",
    )
    parser.add_argument(
        "path", type=Path, nargs="?", metavar="PATH", help="texture set or project to open"
    )
    parser.set_defaults(verb_module=VERB_MODULE)


def run(args: Any) -> int:
    return start(getattr(args, "path", None))


def start(path: Path | None = None, argv: list[str] | None = None) -> int:
    """Run the editor until its window closes; returns the exit status."""
    import sys

    from PySide6.QtWidgets import QApplication

    from .main_window import MainWindow
    from .theme import apply_theme

    app = QApplication.instance() or QApplication(argv if argv is not None else sys.argv[:1])
    app.setApplicationName("matshop")
    app.setOrganizationName("matshop")
    apply_theme(app)
    window = MainWindow()
    window.show()
    if path is not None:
        window.open_path(path)
    return int(app.exec())
