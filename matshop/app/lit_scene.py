"""What the canvas' lit display shows: the swatch scene, its light, and the reference render.

Both renderers of the lit display read their settings here, so the OpenGL
pass (:mod:`.lit_gl`) and the reference fallback draw the same picture: the
flattened material as :func:`matshop.render.scenes.swatch` (one pixel per
texel, tilted 30 degrees towards the sky), one directional light, a quarter
of the lighting environment the artist chose (:mod:`.lighting`: the studio
unless View > Lighting says otherwise; a quarter, so the light dragged over the
canvas keeps raking the relief), 4 environment samples per pixel, the chosen
exposure.
"""

from __future__ import annotations

import math

import numpy as np

from ..material import Material
from ..render import scenes
from ..render.environment import Environment
from ..render.integrator import DirectionalLight
from ..render.render import render

#: How far (0..1) the light may lean away from straight above at the image's edge.
MAX_TILT = 0.85
LIGHT_IRRADIANCE = (3.0, 3.0, 3.0)
ENVIRONMENT_SCALE = 0.25
SAMPLES = 4
TILT_DEG = 30.0
BACKGROUND = (0.12, 0.12, 0.13)


def light_direction(u: float, v: float) -> tuple[float, float, float]:
    """World direction towards the light for a point (u, v) in [-1, 1] of the image.

    The swatch lies in the x-y plane facing +z; image down is -y.
    """
    x, y = MAX_TILT * max(-1.0, min(u, 1.0)), -MAX_TILT * max(-1.0, min(v, 1.0))
    z = math.sqrt(max(1.0 - x * x - y * y, 0.05))
    return (x, y, z)


def lights(direction: tuple[float, float, float]) -> tuple[DirectionalLight, ...]:
    return (DirectionalLight(direction, LIGHT_IRRADIANCE),)


def to_rgba8(display: np.ndarray) -> np.ndarray:
    """A renderer's display values in [0, 1] as opaque RGBA8 codes (rounded, not truncated)."""
    rgba = np.clip(display * 255.0 + 0.5, 0, 255).astype(np.uint8)
    rgba[..., 3] = 255
    return np.ascontiguousarray(rgba)


def reference_image(
    material: Material,
    direction: tuple[float, float, float],
    shape: tuple[int, int],
    progress=None,
    *,
    environment: Environment | None = None,
    exposure_stops: float = 0.0,
) -> np.ndarray:
    """The reference renderer's lit swatch of ``shape`` (height, width) pixels, as RGBA8
    (``environment`` None: the studio)."""
    image = render(
        material,
        scene=scenes.swatch(shape, tilt_deg=TILT_DEG),
        environment=environment,
        size=max(shape),
        lights=lights(direction),
        environment_scale=ENVIRONMENT_SCALE,
        samples=SAMPLES,
        background=BACKGROUND,
        progress=progress,
    )
    return to_rgba8(image.display(exposure=exposure_stops))
