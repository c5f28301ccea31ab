"""The curves dialog's axes in the units artists know: physical values, not edit numbers.

A tone curve acts in edit space: its [0, 1] axis stands for ``lo + t * span``
edit values of one channel group (the op's tone range,
:mod:`matshop.ops.tone_range`). The dialog keeps that axis, so the curve
still acts exactly as the op defines it, but labels it with what the file
would hold there: ``from_edit(lo + t * span)``, a roughness 0-1, a color as
the file's 8-bit code, a normal's tilt in degrees (a frame's edit magnitude
is half its rotation angle), a Phong exponent. Qt-free.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..material import Parameter


class ToneSpan(Protocol):
    """What [0, 1] of a curve stands for, per channel (a vector: its magnitude)."""

    vector: bool
    lo: np.ndarray
    span: np.ndarray


@dataclass(frozen=True)
class PhysicalAxis:
    """Physical values along a curve axis ``t`` of one parameter."""

    param: Parameter
    lo: np.ndarray
    span: np.ndarray
    vector: bool

    @property
    def unit(self) -> str:
        space = self.param.space.name
        if self.vector and space.startswith("normal"):
            return "tilt (degrees)"
        if space in ("srgb", "gamma22"):
            return "file code (0-255)"
        return self.param.label

    def values(self, t: np.ndarray | float) -> np.ndarray:
        """``(n, k)`` physical values at curve positions ``t`` (``n`` of them), per channel."""
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        edit = self.lo[None, :] + t[:, None] * self.span[None, :]
        if self.vector:
            if self.param.space.name.startswith("normal"):
                return np.degrees(2.0 * edit)  # |log q| is half the rotation angle
            return edit  # a sampled function's magnitude has no file unit
        width = self.param.space.edit_channels
        block = np.broadcast_to(edit[:, None, :], (edit.shape[0], 1, width)).astype(np.float32)
        phys = self.param.space.from_edit(np.ascontiguousarray(block))[:, 0, :].astype(float)
        if self.param.space.name in ("srgb", "gamma22"):
            return np.round(255.0 * phys)
        return phys

    def text(self, t: float) -> str:
        """The physical value at ``t``: one number, or one per channel when they differ."""
        values = self.values(t)[0]
        if self.vector and self.param.space.name.startswith("normal"):
            return f"{values[0]:.1f}°"
        if self.param.space.name in ("srgb", "gamma22"):
            codes = [int(v) for v in values]
            return str(codes[0]) if max(codes) - min(codes) <= 1 else "/".join(map(str, codes))
        return " ".join(_number(v) for v in np.unique(np.round(values, 4)))

    def ticks(self, count: int = 5) -> list[tuple[float, str]]:
        """About ``count`` ticks: round physical values where the axis has one channel
        (placed where the curve's axis holds them), else evenly spaced positions
        labelled with each channel's value."""
        even = [(float(t), self.text(float(t))) for t in np.linspace(0.0, 1.0, count)]
        if self.lo.size != 1 or self.param.space.name in ("srgb", "gamma22"):
            return even
        dense = np.linspace(0.0, 1.0, 257)
        values = self.values(dense)[:, 0]
        low, high = float(values.min()), float(values.max())
        if not np.isfinite([low, high]).all() or high - low <= 0:
            return even
        step = _nice_step((high - low) / max(count - 1, 1))
        nice = np.arange(np.ceil(low / step) * step, high + 0.5 * step, step)
        # where on the axis each value sits: the first t reaching it (the axis is monotone
        # but may be flat where from_edit clamps out-of-range edit values)
        increasing = values[-1] >= values[0]
        ticks = []
        for value in nice:
            reached = values >= value - 1e-9 if increasing else values <= value + 1e-9
            if reached.any():
                i = int(np.argmax(reached))
                t = float(dense[i])
                if i > 0 and values[i] != values[i - 1]:  # linear between the samples
                    share = (value - values[i - 1]) / (values[i] - values[i - 1])
                    t = float(dense[i - 1] + share * (dense[i] - dense[i - 1]))
                ticks.append((t, self.text(t) if step < 1e-3 else _number(float(value))))
        if self.vector and self.param.space.name.startswith("normal"):
            ticks = [(t, f"{float(label):.0f}°") for t, label in ticks]
        return ticks if len(ticks) >= 2 else even


def _nice_step(raw: float) -> float:
    """1, 2, 2.5 or 5 times a power of ten, at least ``raw``."""
    power = 10.0 ** np.floor(np.log10(raw))
    for factor in (1.0, 2.0, 2.5, 5.0, 10.0):
        if factor * power >= raw - 1e-12:
            return float(factor * power)
    return float(10.0 * power)


def _number(value: float) -> str:
    if abs(value) >= 100:
        return f"{value:.0f}"
    if abs(value) >= 10:
        return f"{value:.1f}"
    return f"{value:.2f}"


def physical_axis(param: Parameter, tone: ToneSpan) -> PhysicalAxis:
    """The physical labelling of the curve axis of ``param`` over ``tone``."""
    lo = np.asarray(tone.lo, dtype=np.float64).reshape(-1)
    span = np.asarray(tone.span, dtype=np.float64).reshape(-1)
    if not tone.vector and lo.size != param.space.edit_channels:
        raise ValueError(
            f"{param.name}: a tone range of {lo.size} channel(s) for "
            f"{param.space.edit_channels} edit channel(s)"
        )
    return PhysicalAxis(param, lo, span, bool(tone.vector))
