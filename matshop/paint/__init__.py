"""The brush engine: strokes of (x, y, pressure) samples become dabs in edit space.

Qt-free. Modules, one idea each:

- :mod:`.pressure` — :class:`PressureCurve`, pressure -> factor from control points
- :mod:`.brush` — :class:`Brush` settings and the dab footprint
- :mod:`.stroke` — :class:`StrokeSample`, :class:`Stroker` (dab placement by spacing)
- :mod:`.swatch` — :class:`Swatch` (a material to paint) and swatch libraries
- :mod:`.symmetry` — :class:`Symmetry`, mirror images of a dab about the centre lines
- :mod:`.painter` — :class:`StrokeSession`, painting, erasing and clone stamping
  into a layer's pixels or mask, one history step per stroke
"""

from .brush import Brush, dab_footprint
from .painter import StrokeSession, paint_stroke
from .pressure import PressureCurve
from .stroke import Dab, Stroker, StrokeSample
from .swatch import Swatch, load_swatches, save_swatches
from .symmetry import Symmetry

__all__ = [
    "Brush",
    "Dab",
    "PressureCurve",
    "StrokeSample",
    "StrokeSession",
    "Stroker",
    "Swatch",
    "Symmetry",
    "dab_footprint",
    "load_swatches",
    "paint_stroke",
    "save_swatches",
]
