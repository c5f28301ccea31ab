"""Linear scalar data (metallic, ambient occlusion, opacity, height, masks).

These are already linear in what they mean, so the edit space is the
identity; ``from_edit`` clamps to the physical range.
"""

from __future__ import annotations

import numpy as np

from ._kernels import IDENTITY, Step
from .base import EditRange, FusedSpace, Space, as_channels


class IdentitySpace(FusedSpace):
    """Edit value == physical value; clamped to ``[lo, hi]`` on the way back."""

    curve_mode = "channels"

    def __init__(
        self, channels: int = 1, lo: float = 0.0, hi: float = 1.0, name: str = "identity"
    ) -> None:
        self.name = name
        self.description = f"linear data, identity edit space, clamped to [{lo:g}, {hi:g}]"
        self.phys_channels = channels
        self.edit_channels = channels
        self.lo = lo
        self.hi = hi
        bounded = np.isfinite(lo) and np.isfinite(hi)
        # unbounded data still needs a typical extent for curves and bilateral distances
        self.edit_range = EditRange(lo, hi) if bounded else EditRange(0.0, 1.0)

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        checked = as_channels(phys, self.phys_channels, self.name)
        # a plain copy is a memcpy; as_channels has already copied when it converted
        return checked.copy() if np.may_share_memory(checked, phys) else checked

    def to_edit_step(self) -> Step:
        return Step(False, IDENTITY)

    def from_edit_step(self) -> Step:
        return Step(False, IDENTITY, lo=self.lo, hi=self.hi)


SPACES: dict[str, Space] = {
    "identity": IdentitySpace(),
    # height / displacement from float files may leave [0, 1]; nothing to clamp to
    "identity_unbounded": IdentitySpace(
        lo=float("-inf"), hi=float("inf"), name="identity_unbounded"
    ),
}
