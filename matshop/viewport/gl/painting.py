"""Painting on the mesh: cursor -> surface points -> dabs projected in 3D -> the brush engine.

What a dab is here. The 2D canvas stamps a disc in texel space; on a mesh
that disc would stop at every UV seam and stretch where the mapping does.
So a dab on the mesh is a *ball* around the surface point under the cursor,
with the brush's radius converted to world units by the texel size there
(:meth:`.surface_map.SurfaceMap.texel_world_at`): every texel whose surface
point lies inside is painted, with the brush's falloff applied to the
distance measured in those texel units (for a flat, uniformly mapped surface
this is exactly :func:`matshop.paint.brush.dab_footprint`). Texels on both
sides of a seam, in any UV island or repeat, are painted by the same dab, so
a stroke continues across seams with no gap; padded gutter texels are
painted with their island's edge (edge padding). Texels whose surface faces
away from the dab's normal are left alone (no painting through thin shells).

Dabs are spaced along the stroke's path on the surface (``brush.step_at``
texels, measured in world units through the texel size), from surface
points the viewport samples at most one screen pixel apart, so a fast
stroke does not cut through the inside of the mesh.

Everything else is the brush engine's: :class:`SurfaceStroke` is a
:class:`~matshop.paint.painter.StrokeSession` (the same stroke buffer,
wash-mode opacity, paint transaction, one undo step per stroke); only where
a dab's alpha lands differs.

Symmetry in object space: with a :class:`~.mirror.MeshMirror`, every dab
also paints its image across the mirror plane (the surface point nearest to
its reflection, in that point's own UV chart and texel size), into the same
stroke buffer: one stroke, one undo step, as the 2D canvas's mirror images.

With a brush tip the dab is the tip laid in the tangent plane instead of the
ball (:mod:`.surface_tip`), shaped by the brush's dynamics as on the canvas:
fixed / follow / random rotation and angle jitter in texel space (follow
takes the stroke's step on the surface), size jitter, and scatter along /
across the step in the tangent plane. The first dab of a run has no step
yet: follow and scatter take heading 0 (texel +x) there. A mirror image is
the same dab reflected (its tip frame is the reflected frame).

A stencil on the 3D view (:class:`.screen_stencil.ScreenStencil`) masks each
dab, round or tip, and each mirror image, at the screen point where its
texels' surface points show.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from ...layers.geometry import Rect
from ...paint.brush import Brush
from ...paint.painter import StrokeSession
from .mirror import MeshMirror
from .picking import SurfaceHit
from .screen_stencil import ScreenStencil
from .surface_map import SurfaceMap
from .surface_tip import heading, tip_alpha, tip_frame, tip_reach


def falloff(distance: np.ndarray, radius: float, hardness: float) -> np.ndarray:
    """The brush's alpha at ``distance`` texels from the centre (as :func:`dab_footprint`)."""
    outer = radius + 0.5
    inner = max(min(hardness * radius, radius - 0.5), 0.0)
    t = np.clip((outer - distance) / (outer - inner), 0.0, 1.0)
    return (t * t * (3.0 - 2.0 * t)).astype(np.float32)


class SurfaceStroke(StrokeSession):
    """A stroke of 3D dabs on a baked surface (see the module docstring).

    Takes :class:`~.picking.SurfaceHit` points instead of texel samples;
    ``end`` / ``cancel`` and the undo step are the brush engine's.
    """

    def __init__(
        self,
        doc,
        layer_id: int,
        brush: Brush,
        surface: SurfaceMap,
        *,
        mirror: MeshMirror | None = None,
        screen_stencil: ScreenStencil | None = None,
        **options,
    ) -> None:
        super().__init__(doc, layer_id, brush, **options)
        self.surface = surface
        self.mirror = mirror
        self.screen_stencil = screen_stencil
        self._last: tuple[SurfaceHit, float] | None = None
        self._to_next = 0.0  # texels left to walk before the next dab

    def add_hits(self, hits: Iterable[tuple[SurfaceHit, float]]) -> int:
        """Feed (surface point, pressure) pairs in stroke order; returns the dabs placed."""
        placed = 0
        brush = self.brush
        for hit, pressure in hits:
            last = self._last
            self._last = (hit, pressure)
            if last is None:
                self.stamp(hit, pressure, None)
                self._to_next = brush.step_at(pressure)
                placed += 1
                continue
            prev, prev_pressure = last
            texel = self.surface.texel_world_at(hit.uv)
            length = float(np.linalg.norm(hit.position - prev.position)) / max(texel, 1e-12)
            walked = 0.0
            while length > 0.0 and length - walked >= self._to_next:
                walked += self._to_next
                t = walked / length
                p = prev_pressure + t * (pressure - prev_pressure)
                normal = prev.normal + t * (hit.normal - prev.normal)
                point = SurfaceHit(
                    position=prev.position + t * (hit.position - prev.position),
                    normal=normal / max(np.linalg.norm(normal), 1e-12),
                    uv=hit.uv if t > 0.5 else prev.uv,
                )
                self.stamp(point, p, hit.position - prev.position)
                placed += 1
                self._to_next = brush.step_at(p)
            self._to_next -= length - walked
        return placed

    def lift(self) -> None:
        """The cursor left the surface: the next point starts a new run of dabs."""
        self._last = None

    def stamp(self, hit: SurfaceHit, pressure: float, step: np.ndarray | None = None) -> None:
        """One dab at ``hit`` and, with a mirror, its image across the plane.

        ``step``: the stroke's world step into this dab (for follow and scatter).
        """
        if self.brush.tip is not None:
            self._stamp_tip(hit, pressure, step)
        else:
            self._ball(hit, pressure)
            if self.mirror is not None:
                self._ball(self.mirror.image(hit), pressure)
        self.dabs += 1

    def _stamp_tip(self, hit: SurfaceHit, pressure: float, step: np.ndarray | None) -> None:
        frame = tip_frame(self.surface, hit)
        direction = None if step is None else heading(step, frame)
        placed = self._shaper.place(0.0, 0.0, self.brush.radius_at(pressure), direction)
        self._tip(hit, frame, placed, pressure)
        if self.mirror is not None:
            image = self.mirror.image(hit)
            plane = self.mirror.plane
            t, b = (plane.reflect_vector(v) for v in frame)
            self._tip(image, _in_plane(t, b, image.normal), placed, pressure)

    def _tip(self, hit: SurfaceHit, frame, placed, pressure: float) -> None:
        """The tip dab ``placed`` (offset, radius, angle in texels) in ``frame`` at ``hit``."""
        texel = self.surface.texel_world_at(hit.uv)
        t, b = frame
        centre = hit.position + (placed.x * t + placed.y * b) * texel
        reach = tip_reach(self.brush, placed.radius_px) * texel
        flow = np.float32(self.brush.flow_at(pressure))
        for key, (points, inside) in sorted(
            self.surface.ball_points(centre, reach, hit.normal).items()
        ):
            d = (points - centre.astype(np.float32)) / np.float32(texel)
            offsets = np.stack([d @ t.astype(np.float32), d @ b.astype(np.float32)], axis=-1)
            alpha = tip_alpha(self.brush, offsets, inside, placed.radius_px, placed.angle_deg)
            self._stamp_tile(key, alpha, points, flow, pressure)

    def _ball(self, hit: SurfaceHit, pressure: float) -> None:
        """A ball of the brush's radius (in texels at ``hit``) around ``hit``."""
        brush = self.brush
        radius = brush.radius_at(pressure)
        texel = self.surface.texel_world_at(hit.uv)
        reach = (radius + 0.5) * texel
        flow = np.float32(brush.flow_at(pressure))
        centre = np.asarray(hit.position, np.float32)
        for key, (points, inside) in sorted(
            self.surface.ball_points(hit.position, reach, hit.normal).items()
        ):
            distance = np.linalg.norm(points - centre, axis=-1)
            alpha = np.where(inside, falloff(distance / texel, radius, brush.hardness), 0.0)
            self._stamp_tile(key, alpha, points, flow, pressure)

    def _stamp_tile(
        self, key, alpha: np.ndarray, points: np.ndarray, flow: np.float32, pressure: float
    ) -> None:
        """Add a dab's ``alpha`` over tile ``key`` (cropped to its nonzero box), through
        the screen stencil at the texels' surface ``points``."""
        rows = np.nonzero(alpha.any(axis=1))[0]
        cols = np.nonzero(alpha.any(axis=0))[0]
        if rows.size == 0:
            return
        if self.screen_stencil is not None:
            box = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
            alpha = alpha.copy()
            alpha[box] *= self.screen_stencil.at(points[box])
        tile = self.doc.layout.tile_rect(key)
        rect = Rect(
            tile.x0 + int(cols[0]),
            tile.y0 + int(rows[0]),
            tile.x0 + int(cols[-1]) + 1,
            tile.y0 + int(rows[-1]) + 1,
        )
        block = alpha[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
        self.stamp_alpha(rect, flow * block.astype(np.float32), self.brush.opacity_at(pressure))


def _in_plane(t: np.ndarray, b: np.ndarray, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``t``, ``b`` made an orthonormal pair in the plane across ``normal``."""
    n = np.asarray(normal, np.float64)
    t = t - (t @ n) * n
    t = t / max(np.linalg.norm(t), 1e-12)
    b = b - (b @ n) * n - (b @ t) * t
    return t, b / max(np.linalg.norm(b), 1e-12)


class ViewportPainter:
    """Mouse press / move / release in widget pixels -> a :class:`SurfaceStroke`.

    ``pick(x, y)`` returns the :class:`SurfaceHit` under a widget point (or None);
    ``surface()`` the current bake; ``make_stroke()`` keyword arguments for the
    session (layer, brush, swatch, history) come from the caller.
    """

    def __init__(
        self,
        pick: Callable[[float, float], SurfaceHit | None],
        surface: Callable[[], SurfaceMap],
        session_options: Callable[[], dict],
    ) -> None:
        self._pick = pick
        self._surface = surface
        self._options = session_options
        self.stroke: SurfaceStroke | None = None
        self._cursor: tuple[float, float] | None = None

    @property
    def active(self) -> bool:
        return self.stroke is not None

    def press(self, x: float, y: float, pressure: float = 1.0) -> int:
        options = dict(self._options())
        doc = options.pop("doc")
        layer_id = options.pop("layer_id")
        brush = options.pop("brush")
        self.stroke = SurfaceStroke(doc, layer_id, brush, self._surface(), **options)
        self._cursor = (x, y)
        hit = self._pick(x, y)
        return self.stroke.add_hits([(hit, pressure)]) if hit is not None else 0

    def move(self, x: float, y: float, pressure: float = 1.0) -> int:
        """Walk from the last cursor position in steps of at most one pixel."""
        if self.stroke is None or self._cursor is None:
            return 0
        x0, y0 = self._cursor
        self._cursor = (x, y)
        steps = max(1, int(np.ceil(np.hypot(x - x0, y - y0))))
        placed = 0
        for k in range(1, steps + 1):
            t = k / steps
            hit = self._pick(x0 + t * (x - x0), y0 + t * (y - y0))
            if hit is None:
                self.stroke.lift()
                continue
            placed += self.stroke.add_hits([(hit, pressure)])
        return placed

    def release(self):
        """End the stroke: returns its edit (None if it painted nothing)."""
        stroke, self.stroke = self.stroke, None
        self._cursor = None
        return None if stroke is None else stroke.end()
