"""Far-field appearance: does a downsized material look like the full one seen from afar?

What the eye sees of a material from ``factor`` times farther away is the
full-resolution material rendered at full size with each ``factor x factor``
block of pixels averaged (linear radiance). A downsized material rendered at
the small size, one pixel per texel, should match it; normal detail averaged
away makes highlights too sharp unless the lost tilt variance is kept
(:mod:`matshop.ops.variance`). Measured on the flat swatch scene (one pixel
per texel, no foreshortening) under directional lights only, so renders are
deterministic (no environment sampling noise).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..export.resize import resize_array, resize_material
from ..material import Material
from .integrator import DirectionalLight
from .render import render
from .scenes import swatch

#: swatch tilted 30 deg towards +y, camera on +z: the mirror direction is 60 deg up,
#: so one light sits on the highlight's peak and one on its tail
TILT_DEG = 30.0
LIGHTS = (
    DirectionalLight((0.0, np.sin(np.radians(60.0)), np.cos(np.radians(60.0))), (3.0, 3.0, 3.0)),
    DirectionalLight((0.35, np.sin(np.radians(45.0)), np.cos(np.radians(45.0))), (2.0, 2.0, 2.0)),
)


#: how the full render is brought to the small size (:func:`far_field_renders`)
Truth = Literal["box", "lanczos"]


@dataclass(frozen=True)
class FarFieldError:
    factor: int
    rmse_plain: float
    rmse_kept: float

    @property
    def ratio(self) -> float:
        return self.rmse_kept / self.rmse_plain


def swatch_radiance(material: Material) -> np.ndarray:
    """Linear radiance ``(H, W, 3)``, one pixel per texel, under :data:`LIGHTS`."""
    h, w = material.size
    image = render(
        material, scene=swatch((h, w), tilt_deg=TILT_DEG), lights=LIGHTS, environment_scale=0.0
    )
    return image.radiance


def box_average(image: np.ndarray, factor: int) -> np.ndarray:
    """Mean of each ``factor x factor`` block (the far-away pixel's footprint)."""
    h, w, c = image.shape
    blocks = image[: h - h % factor, : w - w % factor].reshape(
        h // factor, factor, w // factor, factor, c
    )
    return blocks.mean(axis=(1, 3))


@dataclass(frozen=True)
class FarFieldRenders:
    """Linear radiance at the small size: the truth and the two downsized materials."""

    factor: int
    truth: np.ndarray  #: the full-resolution render, box-averaged by ``factor``
    plain: np.ndarray  #: the material downsized by ``factor``
    kept: np.ndarray  #: the same with the lost normal variance kept

    def rmse(self, image: np.ndarray) -> float:
        diff = image - self.truth
        return float(np.sqrt(np.mean(diff * diff)))

    def errors(self) -> FarFieldError:
        return FarFieldError(self.factor, self.rmse(self.plain), self.rmse(self.kept))


def far_field_renders(
    material: Material,
    factor: int,
    *,
    reference: np.ndarray | None = None,
    truth: Truth = "box",
) -> FarFieldRenders:
    """The three images a reduction by ``factor`` is judged on (``reference``: the
    full-resolution :func:`swatch_radiance`, when already rendered).

    ``truth``: the full render averaged over each small pixel's area (``"box"``, what
    the eye integrates) or resampled by the export's own Lanczos-3 (``"lanczos"``, the
    same weights the material's values get: a check that a result does not hinge
    on the two filters differing).
    """
    full = swatch_radiance(material) if reference is None else reference
    h, w = material.size
    size = (h // factor, w // factor)
    plain, kept = (
        swatch_radiance(resize_material(material, size, keep_variance=keep))
        for keep in (False, True)
    )
    far = box_average(full, factor) if truth == "box" else resize_array(full, size)
    return FarFieldRenders(factor, far, plain, kept)


def far_field_errors(
    material: Material,
    factors: tuple[int, ...] = (2, 4, 8),
    *,
    reference: np.ndarray | None = None,
    truth: Truth = "box",
) -> list[FarFieldError]:
    """RMSE against the averaged full render of the downsized material, without and with
    variance kept, per reduction factor (``truth``: :func:`far_field_renders`)."""
    full = swatch_radiance(material) if reference is None else reference
    return [far_field_renders(material, f, reference=full, truth=truth).errors() for f in factors]
