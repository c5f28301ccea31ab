"""Masks generated from the material itself: cavity, edge and ambient occlusion.

No mesh bake is needed: a tangent-space normal map is the gradient of a
height field, so the height is integrated back from the normals
(Frankot and Chellappa 1988: the least-squares surface whose gradient is
closest to the normals' slopes, solved in the Fourier domain, exact for a
tiling texture), and the masks come from that height:

- ``edge`` (convexity) and ``cavity`` are where the surface stands above or
  sinks below its own average over a neighbourhood of ``radius_px``
  (``h - blur(h)``, a band-pass of the height; for a sphere cap of radius R
  it is ``radius_px^2 / R``, i.e. the mean curvature 1/R at that scale);
- ``ao`` is horizon-based ambient occlusion: for each texel and 8 directions
  the highest elevation angle of the height field within ``radius_px``, the
  cosine-weighted sky fraction above it averaged over the directions.

Every mask is shaped by the controls artists expect (:func:`shape_mask`:
level, contrast, blur, invert) and lands in [0, 1]. Heights are in texel
widths, the unit of :func:`matshop.spaces.frame.height_to_normal`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from ..errors import InvalidValue

GENERATORS = ("cavity", "edge", "ao")

#: directions AO searches for the horizon
_AO_DIRECTIONS = 8


def slopes_from_normals(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(dh/dx, dh/dy)`` per texel, x along columns and y down the rows.

    ``normals`` are unit tangent-space normals ``(H, W, 3)`` in the OpenGL
    convention (+Y up the image), so ``dh/dv = -n_y / n_z`` and ``dh/dy = -dh/dv``.
    Grazing normals are clamped to a slope of 20.
    """
    n = np.asarray(normals, dtype=np.float64)
    nz = np.maximum(n[..., 2], 0.05)
    return -n[..., 0] / nz, n[..., 1] / nz


def integrate_height(normals: np.ndarray) -> np.ndarray:
    """The tiling height field (texel units, mean 0) whose gradient best fits ``normals``.

    The spectral derivative is that of central differences (``i sin(w)``), the
    one :func:`~matshop.spaces.frame.height_to_normal` uses, so a height baked
    with ``wrap=True`` comes back exactly, up to its mean and the Nyquist
    components central differences cannot see.
    """
    gx, gy = slopes_from_normals(normals)
    height, width = gx.shape
    wx = np.sin(2.0 * np.pi * np.fft.fftfreq(width))[None, :]
    wy = np.sin(2.0 * np.pi * np.fft.fftfreq(height))[:, None]
    denominator = wx**2 + wy**2
    numerator = -1j * wx * np.fft.fft2(gx) - 1j * wy * np.fft.fft2(gy)
    spectrum = np.divide(
        numerator, denominator, out=np.zeros_like(numerator), where=denominator > 1e-12
    )
    return np.real(np.fft.ifft2(spectrum))


def convexity(height: np.ndarray, radius_px: float) -> np.ndarray:
    """``h - blur(h)`` at the scale ``radius_px`` (a Gaussian of that sigma, wrapped)."""
    from scipy import ndimage  # imported where used: every op loads with the registry

    return height - ndimage.gaussian_filter(height, radius_px, mode="wrap")


def ambient_occlusion(height: np.ndarray, radius_px: float) -> np.ndarray:
    """Horizon-based ambient occlusion in [0, 1] (1: the whole sky is seen)."""
    from scipy import ndimage

    h = np.asarray(height, dtype=np.float64)
    steps = max(1, int(np.ceil(radius_px)))
    visible = np.zeros_like(h)
    for k in range(_AO_DIRECTIONS):
        angle = 2.0 * np.pi * k / _AO_DIRECTIONS
        dx, dy = np.cos(angle), np.sin(angle)
        tangent = np.zeros_like(h)  # the steepest rise seen so far, as a slope
        for step in range(1, steps + 1):
            shifted = ndimage.shift(h, (-dy * step, -dx * step), order=1, mode="wrap")
            tangent = np.maximum(tangent, (shifted - h) / step)
        # a 2D slice of the hemisphere, cosine-weighted: the sky above the
        # horizon at elevation e holds (1 - sin e) of the slice's irradiance
        visible += 1.0 - np.sin(np.arctan(tangent))
    return visible / _AO_DIRECTIONS


def shape_mask(
    values: np.ndarray,
    *,
    level: float = 0.5,
    contrast: float = 1.0,
    blur_px: float = 0.0,
    invert: bool = False,
) -> np.ndarray:
    """Artist controls on a raw mask in [0, 1]: ``level`` is what maps to 0.5, ``contrast``
    the slope there, ``blur_px`` a Gaussian softening, ``invert`` flips it."""
    shaped = np.clip(0.5 + contrast * (np.asarray(values, np.float64) - level), 0.0, 1.0)
    if blur_px > 0:
        from scipy import ndimage

        shaped = ndimage.gaussian_filter(shaped, blur_px, mode="wrap")
    return 1.0 - shaped if invert else shaped


def generate_mask(
    normals: np.ndarray,
    generator: str,
    *,
    radius_px: float = 4.0,
    level: float = 0.5,
    contrast: float = 1.0,
    blur_px: float = 0.0,
    invert: bool = False,
) -> np.ndarray:
    """A mask ``(H, W)`` float32 in [0, 1] from unit OpenGL normals ``(H, W, 3)``.

    ``cavity`` and ``edge`` are scaled so that the 99th percentile of the
    map's own convexity on that side reaches 1 (what is strongest in this
    material is white, the flat surface black); ``ao`` is the sky fraction
    itself. The controls default to no change (level 0.5, contrast 1).
    """
    if generator not in GENERATORS:
        raise InvalidValue(f"unknown mask generator {generator!r} (known: {', '.join(GENERATORS)})")
    if not (0.0 < radius_px <= 256.0):
        raise InvalidValue(f"radius_px must be in (0, 256], got {radius_px}")
    if not (0.0 <= blur_px <= 256.0):
        raise InvalidValue(f"blur_px must be in [0, 256], got {blur_px}")
    height = integrate_height(normals)
    if generator == "ao":
        raw = ambient_occlusion(height, radius_px)
    else:
        bump = convexity(height, radius_px)
        side = np.maximum(bump if generator == "edge" else -bump, 0.0)
        scale = np.percentile(side, 99.0)
        raw = np.clip(side / scale, 0.0, 1.0) if scale > 0 else side
    shaped = shape_mask(raw, level=level, contrast=contrast, blur_px=blur_px, invert=invert)
    return shaped.astype(np.float32)


@dataclass(frozen=True)
class MaskGenerator:
    """A generated mask as a layer keeps it: the generator and its settings, not pixels.

    A layer holding one shows :meth:`run` on the normals of the material below
    it, recomputed whenever that changes (:mod:`matshop.layers.compositor`).
    The height integration is global (every texel's height depends on every
    normal) and so is the percentile scaling, so a change anywhere below
    changes the whole mask: its reach is the whole image.
    """

    kind: str = "cavity"
    radius_px: float = 4.0
    level: float = 0.5
    contrast: float = 1.0
    blur_px: float = 0.0
    invert: bool = False

    def __post_init__(self) -> None:
        if self.kind not in GENERATORS:
            raise InvalidValue(
                f"unknown mask generator {str(self.kind)[:40]!r} (known: {', '.join(GENERATORS)})"
            )
        for name in ("radius_px", "level", "contrast", "blur_px"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float | np.number):
                raise InvalidValue(f"mask generator {name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise InvalidValue(f"mask generator {name} must be finite, got {value!r}")
            object.__setattr__(self, name, float(value))
        if not isinstance(self.invert, bool | np.bool_):
            raise InvalidValue(f"mask generator invert must be true or false, got {self.invert!r}")
        object.__setattr__(self, "invert", bool(self.invert))
        for name, (lo, hi) in BOUNDS.items():
            value = getattr(self, name)
            low_ok = value > lo if name == "radius_px" else value >= lo
            if not (low_ok and value <= hi):
                opening = "(" if name == "radius_px" else "["
                raise InvalidValue(f"{name} must be in {opening}{lo:g}, {hi:g}], got {value:g}")

    def run(self, normals: np.ndarray) -> np.ndarray:
        """The mask ``(H, W)`` float32 of unit OpenGL ``normals`` ``(H, W, 3)``."""
        settings = self.to_json()
        return generate_mask(normals, settings.pop("kind"), **settings)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_json(cls, data: Any) -> MaskGenerator:
        """From :meth:`to_json`'s form (a project file, the CLI); InvalidValue if wrong."""
        if isinstance(data, MaskGenerator):
            return data
        if not isinstance(data, dict):
            raise InvalidValue(f"a mask generator is an object with a kind, got {data!r}")
        known = {f.name for f in fields(cls)}
        unknown = sorted(str(k)[:40] for k in set(data) - known)
        if unknown:
            raise InvalidValue(
                f"mask generator has unknown setting(s) {', '.join(unknown)} "
                f"(known: {', '.join(sorted(known))})"
            )
        return cls(**data)


#: hard ranges of the settings (radius open at 0); the panel's sliders use them too
BOUNDS: dict[str, tuple[float, float]] = {
    "radius_px": (0.0, 256.0),
    "level": (0.0, 1.0),
    "contrast": (0.0, 64.0),
    "blur_px": (0.0, 256.0),
}
