"""The contract every editing space fulfils.

An editing space converts one material parameter between its *physical*
encoding (what the files hold, decoded to float32) and its *edit* encoding
(what layers hold, where linear image operations respect the parameter's
meaning). Both directions are pure and vectorised over arrays of shape
``(..., C)``: the leading axes are pixels, the last axis is the parameter's
channels.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Literal

import numpy as np

#: How curves and range-normalisation treat the edit channels:
#: ``"channels"`` per channel (colors, scalars), ``"vector"`` by magnitude
#: (frame rotations, inverse CDFs).
CurveMode = Literal["channels", "vector"]


@dataclass(frozen=True)
class EditRange:
    """Typical extent of edit values, for curves and bilateral distances.

    ``lo``/``hi`` bound a single channel (``"channels"`` mode) or the vector
    magnitude (``"vector"`` mode). Values outside are legal in intermediates.
    """

    lo: float
    hi: float

    @property
    def span(self) -> float:
        return self.hi - self.lo


class Space(ABC):
    """An editing space for one parameter family.

    Subclasses set ``name``, ``phys_channels``, ``edit_channels``,
    ``edit_range`` and ``curve_mode`` and implement the two conversions.
    ``to_edit`` and ``from_edit`` never modify their input and always return
    float32 arrays.
    """

    #: registry key, also written into project files
    name: str
    #: one-line description for ``--help`` and the UI
    description: str = ""
    phys_channels: int
    edit_channels: int
    edit_range: EditRange
    curve_mode: CurveMode = "channels"

    @abstractmethod
    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        """Physical values ``(..., phys_channels)`` -> edit values ``(..., edit_channels)``."""

    @abstractmethod
    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        """Edit values ``(..., edit_channels)`` -> physical values ``(..., phys_channels)``.

        Out-of-range edit values are clamped here, never earlier.
        """

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name}: {self.phys_channels}->{self.edit_channels}>"


def as_channels(array: np.ndarray, channels: int, what: str) -> np.ndarray:
    """Check the last axis holds ``channels`` values and return a float32 view or copy."""
    arr = np.asarray(array)
    if arr.ndim == 0 or arr.shape[-1] != channels:
        raise ValueError(
            f"{what}: expected {channels} channel(s) on the last axis, got shape {arr.shape}"
        )
    return arr.astype(np.float32, copy=False)
