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

from .. import buffers
from ._kernels import Step

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

    def to_edit_step(self) -> Step | None:
        """``to_edit`` as one fused kernel step (:class:`._kernels.Step`), or None.

        Spaces with a step are converted together, in one pass over a
        material (:func:`._kernels.run_steps`).
        """
        return None

    def from_edit_step(self) -> Step | None:
        """``from_edit`` as one fused kernel step, or None (see :meth:`to_edit_step`)."""
        return None

    def to_edit_into(self, phys: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``to_edit(phys)`` written into ``out`` (..., edit_channels) float32; returns ``out``.

        ``out`` may be a strided view, e.g. this parameter's channels of a
        material's edit array, and must not overlap ``phys``. This default
        converts, then copies; spaces with a fused kernel override it to
        write in place without temporaries.
        """
        edit = self.to_edit(phys)
        check_out(out, edit.shape[:-1], self.edit_channels, self.name)
        out[...] = edit
        return out

    def from_edit_into(self, edit: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``from_edit(edit)`` written into ``out`` (..., phys_channels) float32; returns ``out``.

        Same rules as :meth:`to_edit_into`.
        """
        phys = self.from_edit(edit)
        check_out(out, phys.shape[:-1], self.phys_channels, self.name)
        out[...] = phys
        return out

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name}: {self.phys_channels}->{self.edit_channels}>"


class FusedSpace(Space):
    """A space whose conversions are one kernel step each, written straight into an output.

    Subclasses implement :meth:`to_edit_step` and :meth:`from_edit_step`;
    ``to_edit`` / ``from_edit`` allocate the output, the ``*_into`` forms
    check a given one.
    """

    def to_edit(self, phys: np.ndarray) -> np.ndarray:
        phys = as_channels(phys, self.phys_channels, self.name)
        out = buffers.empty((*phys.shape[:-1], self.edit_channels))
        return self._to_edit_into(phys, out)

    def from_edit(self, edit: np.ndarray) -> np.ndarray:
        edit = as_channels(edit, self.edit_channels, self.name)
        out = buffers.empty((*edit.shape[:-1], self.phys_channels))
        return self._from_edit_into(edit, out)

    def to_edit_into(self, phys: np.ndarray, out: np.ndarray) -> np.ndarray:
        phys = as_channels(phys, self.phys_channels, self.name)
        check_out(out, phys.shape[:-1], self.edit_channels, self.name)
        return self._to_edit_into(phys, out)

    def from_edit_into(self, edit: np.ndarray, out: np.ndarray) -> np.ndarray:
        edit = as_channels(edit, self.edit_channels, self.name)
        check_out(out, edit.shape[:-1], self.phys_channels, self.name)
        return self._from_edit_into(edit, out)

    @abstractmethod
    def to_edit_step(self) -> Step: ...

    @abstractmethod
    def from_edit_step(self) -> Step: ...

    def _to_edit_into(self, phys: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Float32 ``phys`` (..., phys_channels) -> ``out`` (checked); return ``out``."""
        return self.to_edit_step().run(phys, out)

    def _from_edit_into(self, edit: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Float32 ``edit`` (..., edit_channels) -> ``out`` (checked); return ``out``."""
        return self.from_edit_step().run(edit, out)


def as_channels(array: np.ndarray, channels: int, what: str) -> np.ndarray:
    """Check the last axis holds ``channels`` values and return a float32 view or copy."""
    arr = np.asarray(array)
    if arr.ndim == 0 or arr.shape[-1] != channels:
        raise ValueError(
            f"{what}: expected {channels} channel(s) on the last axis, got shape {arr.shape}"
        )
    return arr.astype(np.float32, copy=False)


def check_out(out: np.ndarray, lead: tuple[int, ...], channels: int, what: str) -> None:
    """Check that ``out`` is a writeable float32 array of shape ``lead + (channels,)``."""
    if not isinstance(out, np.ndarray) or out.dtype != np.float32:
        got = getattr(out, "dtype", type(out).__name__)
        raise TypeError(f"{what}: out must be a float32 ndarray, got {got}")
    if out.shape != (*lead, channels):
        raise ValueError(f"{what}: out must have shape {(*lead, channels)}, got {out.shape}")
    if not out.flags.writeable:
        raise ValueError(f"{what}: out is read-only")
