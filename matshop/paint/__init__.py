"""The brush engine: strokes of (x, y, pressure) samples become dabs in edit space.

Qt-free. Modules, one idea each:

- :mod:`.pressure` — :class:`PressureCurve`, pressure -> factor from control points
- :mod:`.brush` — :class:`Brush` settings and the dab footprint
- :mod:`.tips`, :mod:`.tip_shapes` — :class:`Tip`, grayscale tip images (files or procedural)
- :mod:`.dynamics` — :class:`Dynamics`, tip angle, size/angle jitter and scatter, seeded
- :mod:`.stencil` — :class:`Stencil`, an image masking dabs where it is dark
- :mod:`.sampling` — placing a gray image by a similarity transform, sampling it at texels
- :mod:`.stroke` — :class:`StrokeSample`, :class:`Stroker` (dab placement by spacing)
- :mod:`.swatch` — :class:`Swatch` (a material to paint) and swatch libraries
- :mod:`.symmetry` — :class:`Symmetry`, mirror images of a dab about the centre lines
- :mod:`.painter` — :class:`StrokeSession`, painting, erasing and clone stamping
  into a layer's pixels or mask, one history step per stroke
"""

from .brush import Brush, dab_footprint
from .dynamics import Dynamics
from .painter import StrokeSession, paint_stroke
from .pressure import PressureCurve
from .stencil import Stencil, load_stencil
from .stroke import Dab, Stroker, StrokeSample
from .swatch import Swatch, load_swatches, save_swatches
from .symmetry import Symmetry
from .tips import Tip, load_tip, procedural_tip

__all__ = [
    "Brush",
    "Dab",
    "Dynamics",
    "PressureCurve",
    "StrokeSample",
    "StrokeSession",
    "Stencil",
    "Stroker",
    "Swatch",
    "Symmetry",
    "Tip",
    "dab_footprint",
    "load_stencil",
    "load_swatches",
    "load_tip",
    "paint_stroke",
    "procedural_tip",
    "save_swatches",
]
