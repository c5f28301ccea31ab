"""The engine refuses a user's value with one type, called through the Python API.

Each refusal is an :class:`InvalidValue`: a :class:`MatshopError` (the one type the
command line and the editor catch, printed as one line) and still a ValueError
(a lookup of an unknown name is also a KeyError), so code that caught those keeps
working. The values are ones the documented ranges and names exclude.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from matshop.errors import InvalidValue, MatshopError, UnknownName, naming
from matshop.export.presets import parse_preset
from matshop.layers import Document
from matshop.layers.blend import get_blend_mode
from matshop.material import Schema
from matshop.ops.generators import generate_mask
from matshop.paint import Brush, StrokeSample, Swatch
from matshop.paint.pressure import PressureCurve
from matshop.paint.strokefile import parse_stroke
from matshop.render.tonemap import to_display
from matshop.spaces import get_space
from matshop.spaces.frame import decode_normal_map

SCHEMA = Schema.from_names(["base_color", "roughness"])
FLAT = np.dstack([np.zeros((8, 8, 2), np.float32), np.ones((8, 8, 1), np.float32)])


def _doc() -> Document:
    doc = Document(SCHEMA, 8, 8, name="d")
    doc.insert_layer(doc.new_paint_layer("Paint"))
    return doc


REFUSALS: dict[str, Callable[[], object]] = {
    "space-name": lambda: get_space("bogus"),
    "parameter-name": lambda: Schema.from_names(["sparkle"]),
    "parameter-twice": lambda: Schema.from_names(["roughness", "roughness"]),
    "parameter-lookup": lambda: SCHEMA["metallic"],
    "blend-mode": lambda: get_blend_mode("screen"),
    "opacity": lambda: _doc().new_paint_layer("x", opacity=1.5),
    "visible": lambda: _doc().new_paint_layer("x", visible="maybe"),
    "layer-parameters": lambda: _doc().new_paint_layer("x", parameters=["sheen"]),
    "fill-both": lambda: _doc().new_fill_layer("x"),
    "fill-value-width": lambda: _doc().new_fill_layer("x", value=np.zeros(2, np.float32)),
    "group-blend": lambda: _doc().new_group_layer("g", blend="add"),
    "document-size": lambda: Document(SCHEMA, 0, 8),
    "swatch-values": lambda: Swatch("s", {"roughness": ["x"]}),
    "swatch-empty": lambda: Swatch("s", {}),
    "swatch-parameter": lambda: Swatch("s", {"sheen": [1.0]}).edit_values(SCHEMA),
    "brush-radius": lambda: Brush(radius_px=-1),
    "stroke-pressure": lambda: StrokeSample(0, 0, 2),
    "pressure-curve": lambda: PressureCurve.from_points([[0, 0], [0, 1]]),
    "stroke-brush-setting": lambda: parse_stroke({"points": [[0, 0]], "brush": {"x": 1}}),
    "preset-format": lambda: parse_preset(
        {"name": "p", "maps": [{"channel": "c", "srcMapName": "roughness", "fileFormat": "gif"}]}
    ),
    "mask-generator": lambda: generate_mask(FLAT, "rust"),
    "mask-radius": lambda: generate_mask(FLAT, "cavity", radius_px=0),
    "tone-map": lambda: to_display(np.zeros((2, 2, 3)), tonemap="filmic"),
    "normal-convention": lambda: decode_normal_map(FLAT, convention="vulkan"),
}


@pytest.mark.parametrize("case", list(REFUSALS))
def test_a_refused_value_is_an_invalid_value(case: str) -> None:
    with pytest.raises(InvalidValue) as caught:
        REFUSALS[case]()
    error = caught.value
    assert isinstance(error, MatshopError) and isinstance(error, ValueError)
    assert str(error) and "\n" not in str(error)


@pytest.mark.parametrize("case", ["space-name", "parameter-name", "parameter-lookup"])
def test_an_unknown_name_is_also_a_key_error_that_reads_as_its_sentence(case: str) -> None:
    with pytest.raises(KeyError) as caught:
        REFUSALS[case]()
    assert isinstance(caught.value, UnknownName)
    assert not str(caught.value).startswith(("'", '"'))  # not quoted like a bare KeyError


def test_naming_says_where_and_keeps_the_type() -> None:
    with pytest.raises(InvalidValue) as caught:
        with naming("p.matshop", what="stroke 3"):
            with naming(what="brush"):
                raise InvalidValue("radius_px must be positive")
    assert str(caught.value) == "p.matshop: stroke 3: brush: radius_px must be positive"
    # a file the error already names is kept; the part is still said
    with pytest.raises(InvalidValue) as caught:
        with naming("p.matshop", what="--mask"):
            raise InvalidValue("not an image", "mask.txt")
    assert str(caught.value) == "mask.txt: --mask: not an image"
