"""What every figure function is given and returns, and where the data lives."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import MatshopError
from ..render.environment import Environment
from ..render.render import RenderedImage
from ..render.tonemap import to_uint8

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
