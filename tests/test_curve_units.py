"""The curves dialog's physical axis labels against the spaces' closed forms (MATH.md),
written out here: GGX edit = atan(r^2), Phong edit = acos(2^(-1/(n+2))), colors through
the sRGB encode as 8-bit codes, a frame's edit magnitude = half its tilt."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("PySide6")  # matshop.app imports Qt

from matshop.app.curve_units import physical_axis  # noqa: E402
from matshop.material import Schema  # noqa: E402

SCHEMA = Schema.from_names(["base_color", "roughness", "phong_exponent", "normal", "metallic"])
T = np.linspace(0.0, 1.0, 9)


def tone(lo, span, vector=False):
    return SimpleNamespace(vector=vector, lo=np.array(lo, float), span=np.array(span, float))


def test_ggx_roughness_axis_is_sqrt_tan_of_the_edit_angle() -> None:
    axis = physical_axis(SCHEMA["roughness"], tone([0.1], [0.6]))
    edit = 0.1 + 0.6 * T
    np.testing.assert_allclose(axis.values(T)[:, 0], np.sqrt(np.tan(edit)), atol=2e-5)
    assert axis.text(0.5) == f"{np.sqrt(np.tan(0.4)):.2f}"


def test_phong_axis_is_the_exponent_of_the_median_angle() -> None:
    axis = physical_axis(SCHEMA["phong_exponent"], tone([0.05], [0.5]))
    edit = 0.05 + 0.5 * T
    n = -1.0 / np.log2(np.cos(edit)) - 2.0
    np.testing.assert_allclose(axis.values(T)[:, 0], n, rtol=1e-4)


def test_color_axis_shows_each_channels_file_code() -> None:
    axis = physical_axis(SCHEMA["base_color"], tone([0.0, 0.1, 0.2], [1.0, 0.5, 0.25]))
    linear = np.array([0.0, 0.1, 0.2]) + 0.5 * np.array([1.0, 0.5, 0.25])
    encoded = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    codes = np.round(255 * encoded).astype(int)
    assert axis.text(0.5) == "/".join(str(c) for c in codes)
    assert axis.unit == "file code (0-255)"


def test_normal_axis_is_the_tilt_in_degrees_and_scalars_are_themselves() -> None:
    axis = physical_axis(SCHEMA["normal"], tone([0.0], [np.pi / 4], vector=True))
    assert axis.text(1.0) == "90.0°" and axis.text(0.5) == "45.0°"
    metal = physical_axis(SCHEMA["metallic"], tone([0.2], [0.5]))
    np.testing.assert_allclose(metal.values(T)[:, 0], 0.2 + 0.5 * T, atol=1e-6)
    with pytest.raises(ValueError, match="3 edit channel"):
        physical_axis(SCHEMA["base_color"], tone([0.0], [1.0]))


def test_ticks_are_round_physical_values_placed_where_the_closed_form_reaches_them() -> None:
    lo, span = -0.55, 1.23  # a data range reaching below the space's 0 (clamped going back)
    axis = physical_axis(SCHEMA["roughness"], tone([lo], [span]))
    ticks = axis.ticks(5)
    labels = [float(label) for _, label in ticks]
    assert labels == [0.0, 0.25, 0.5, 0.75]
    for t, value in zip([t for t, _ in ticks], labels, strict=True):
        edit = np.clip(lo + t * span, 0.0, np.pi / 4)
        assert np.sqrt(np.tan(edit)) == pytest.approx(value, abs=2e-3)
    tilt = physical_axis(SCHEMA["normal"], tone([0.0], [0.3], vector=True)).ticks(5)
    assert [label for _, label in tilt] == ["0°", "10°", "20°", "30°"]
    assert [t for t, _ in tilt] == pytest.approx([np.radians(d) / 2 / 0.3 for d in (0, 10, 20, 30)])
