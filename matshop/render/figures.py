"""``matshop figures OUTDIR``: the seed paper's figures, each with the number that makes its point.

Each figure function takes a :class:`FigureContext` and returns a
:class:`FigureResult` (the PNG it wrote and a one-line measurement). The
figures live in their own modules: :mod:`.fig_strips` (Fig. 3),
:mod:`.fig_plots` (Figs. 4, 5, 6), :mod:`.fig_edits` (Figs. 2, 7),
:mod:`.fig_aniso` (Fig. 7(h)), :mod:`.fig_steep` (Fig. 2 on synthetic relief),
:mod:`.fig_subsurface` (Fig. 8), :mod:`.fig_paint` (Fig. 9),
:mod:`.fig_sequences` (Fig. 1).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import MatshopError
from .environment import Environment, studio
from .render import RenderedImage
from .tonemap import to_uint8

ROOT = Path(__file__).resolve().parents[2]
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
SAMPLE = ROOT / "resources" / "sample"


@dataclass
class FigureResult:
    name: str
    path: Path
    measurement: str
    values: dict[str, float] = field(default_factory=dict)


@dataclass
class FigureContext:
    outdir: Path
    data: Path
    environment: Environment

    def save(self, name: str, image: np.ndarray) -> Path:
        """Write an RGB uint8 image as ``OUTDIR/name.png`` (optimised 8-bit PNG)."""
        import cv2

        path = self.outdir / f"{name}.png"
        ok = cv2.imwrite(str(path), image[..., ::-1], [cv2.IMWRITE_PNG_COMPRESSION, 9])
        if not ok:
            raise MatshopError("cannot write the figure", path)
        return path


def display(image: RenderedImage, *, exposure: float = 0.0, tonemap: str = "aces") -> np.ndarray:
    """A render as an RGB uint8 tile."""
    return to_uint8(image.display(exposure=exposure, tonemap=tonemap)[..., :3])


#: figure name -> (module, function)
FIGURES: dict[str, tuple[str, str]] = {
    "fig1": ("fig_sequences", "fig1"),
    "fig3": ("fig_strips", "fig3"),
    "fig5": ("fig_plots", "fig5"),
    "fig2": ("fig_edits", "fig2"),
    "fig2s": ("fig_steep", "fig2_synthetic"),
    "fig4": ("fig_plots", "fig4"),
    "fig6": ("fig_plots", "fig6"),
    "fig7": ("fig_edits", "fig7"),
    "fig7h": ("fig_aniso", "fig7h"),
    "fig8": ("fig_subsurface", "fig8"),
    "fig9": ("fig_paint", "fig9"),
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
