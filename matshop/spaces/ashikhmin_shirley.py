"""Ashikhmin-Shirley exponents ``(nu, nv)``: two independent Phong coordinates.

The anisotropic lobe ``cos^(nu cos^2 phi + nv sin^2 phi) theta`` is a Phong lobe
along each tangent axis, and the axes rotate with the local frame, so each
exponent is edited exactly like a Phong exponent, channel by channel: this
module reuses :mod:`matshop.spaces.phong`'s coordinate maps (and its clamp to
``[0, phong.N_MAX]``) rather than repeating them. The default coordinate is
Phong's (``phong.DEFAULT_COORDINATE``, the median angle, chosen by measurement
there); ``ashikhmin_shirley_paper`` is the seed paper's ``1/sqrt(n)``.
"""

from __future__ import annotations

from .base import Space
from .phong import COORDINATES, DEFAULT_COORDINATE, PhongSpace


class AshikhminShirleySpace(PhongSpace):
    """``(nu, nv)`` <-> two edit channels, each a Phong coordinate."""

    family = "ashikhmin_shirley"

    def __init__(self, coordinate: str, *, name: str | None = None) -> None:
        super().__init__(coordinate, name=name, channels=2)

    def _what(self) -> str:
        return "Ashikhmin-Shirley exponents (nu, nv), each"


SPACES: dict[str, Space] = {
    "ashikhmin_shirley": AshikhminShirleySpace(DEFAULT_COORDINATE, name="ashikhmin_shirley"),
    **{f"ashikhmin_shirley_{key}": AshikhminShirleySpace(key) for key in COORDINATES},
}
