"""``matshop figures OUTDIR``: the seed paper's figures, each with the number that makes its point.

Each figure function takes a :class:`FigureContext` and returns a
:class:`FigureResult` (the PNG it wrote and a one-line measurement). The
figures live in their own modules: :mod:`.strips` (Fig. 3),
:mod:`.plots` (Figs. 4, 5, 6), :mod:`.edits` (Figs. 2, 7),
:mod:`.aniso` (Fig. 7(h)), :mod:`.steep` (Fig. 2 on synthetic relief),
:mod:`.subsurface` (Fig. 8), :mod:`.paint` (Fig. 9),
:mod:`.sequences` (Fig. 1).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from pathlib import Path

from ..errors import MatshopError
from ..render.environment import studio
from .context import CHESSBOARD, SAMPLE, FigureContext, FigureResult

#: figure name -> (module, function)
FIGURES: dict[str, tuple[str, str]] = {
    "fig1": ("sequences", "fig1"),
    "fig3": ("strips", "fig3"),
    "fig5": ("plots", "fig5"),
    "fig2": ("edits", "fig2"),
    "fig2s": ("steep", "fig2_synthetic"),
    "fig4": ("plots", "fig4"),
    "fig6": ("plots", "fig6"),
    "fig7": ("edits", "fig7"),
    "fig7h": ("aniso", "fig7h"),
    "fig8": ("subsurface", "fig8"),
    "fig9": ("paint", "fig9"),
}


def _function(name: str) -> Callable[[FigureContext], FigureResult]:
    module, func = FIGURES[name]
    return getattr(importlib.import_module(f"{__package__}.{module}"), func)


def make_figures(
    outdir: str | os.PathLike[str],
    *,
    only: list[str] | None = None,
    data: str | os.PathLike[str] | None = None,
) -> list[FigureResult]:
    """Render the figures named in ``only`` (default: all) into ``outdir``."""
    names = list(FIGURES) if not only else only
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        raise MatshopError(f"unknown figure(s) {', '.join(unknown)} (known: {', '.join(FIGURES)})")
    out = Path(outdir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MatshopError(exc.strerror or "cannot create the folder", out) from None
    source = Path(data) if data is not None else (CHESSBOARD if CHESSBOARD.is_dir() else SAMPLE)
    ctx = FigureContext(out, source, studio())
    return [_function(name)(ctx) for name in names]
