"""The 3D mirror's geometry without OpenGL: closest points on triangles against a brute
force search over dense samples of each triangle, and the image of a surface point on
meshes whose mirror images are known (a generated sphere: the reflection itself)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("OpenGL.GL", reason="PyOpenGL (extra 'gui') not installed")

from matshop.viewport.gl.mesh_data import uv_sphere  # noqa: E402
from matshop.viewport.gl.mirror import (  # noqa: E402
    MeshMirror,
    MirrorPlane,
    closest_on_triangle,
    closest_on_triangles,
)
from matshop.viewport.gl.picking import SurfaceHit  # noqa: E402


def brute_force(point: np.ndarray, a, b, c, k: int = 160) -> float:
    """Distance from ``point`` to the nearest of ~k^2/2 points spread over the triangle."""
    i, j = np.mgrid[0 : k + 1, 0 : k + 1]
    keep = i + j <= k
    u, v = i[keep] / k, j[keep] / k
    samples = u[:, None] * a + v[:, None] * b + (1 - u - v)[:, None] * c
    return float(np.linalg.norm(samples - point, axis=1).min())


def test_closest_points_on_triangles_match_a_brute_force_search() -> None:
    rng = np.random.default_rng(7)
    a, b, c = (rng.normal(size=(60, 3)) for _ in range(3))
    c[:5] = a[:5] + 0.3 * (b[:5] - a[:5])  # degenerate: collinear corners
    b[5:8] = a[5:8]  # degenerate: two corners in one place
    for _ in range(12):
        point = rng.normal(size=3) * 2.0
        found, bary = closest_on_triangles(point, a, b, c)
        assert np.allclose(bary.sum(axis=1), 1.0) and (bary > -1e-9).all()
        corners = bary[:, :1] * a + bary[:, 1:2] * b + bary[:, 2:] * c
        np.testing.assert_allclose(found, corners, atol=1e-12)
        for t in range(0, 60, 3):
            exact = float(np.linalg.norm(found[t] - point))
            sampled = brute_force(point, a[t], b[t], c[t])
            # never farther than any sample; no farther than the samples' spacing beyond them
            assert exact <= sampled + 1e-9
            spacing = (np.linalg.norm(b[t] - a[t]) + np.linalg.norm(c[t] - a[t])) / 160
            assert sampled - exact <= spacing + 1e-9


def test_one_triangle_in_plain_floats_gives_the_vectorised_bits() -> None:
    """Every region, and degenerate triangles (collinear, coincident corners, a point)."""
    rng = np.random.default_rng(3)
    a, b, c = (rng.normal(size=(300, 3)) for _ in range(3))
    c[:20] = a[:20] + 0.3 * (b[:20] - a[:20])
    b[20:40] = a[20:40]
    b[40:50] = c[40:50] = a[40:50]
    for point in rng.normal(size=(40, 3)) * 2.0:
        points, barys = closest_on_triangles(point, a, b, c)
        for t in range(len(a)):
            found, bary = closest_on_triangle(tuple(point), tuple(a[t]), tuple(b[t]), tuple(c[t]))
            assert found == tuple(points[t]) and bary == tuple(barys[t]), t


def test_the_nearest_point_of_a_mesh_is_the_exhaustive_searchs() -> None:
    """Against every triangle at once: points on, near, inside and far from a lumpy
    (asymmetric) sphere; the far ones need more than the few nearest centroids."""
    mesh = uv_sphere(48, 24)
    rng = np.random.default_rng(4)
    lumps = 1.0 + 0.15 * rng.random(len(mesh.positions))
    mesh = dataclasses.replace(mesh, positions=(mesh.positions * lumps[:, None]).astype(np.float32))
    mirror = MeshMirror(mesh, MirrorPlane("x"))
    corners = mesh.positions.astype(np.float64)[mesh.indices.astype(np.int64)]
    directions = rng.normal(size=(120, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    scales = np.concatenate([rng.uniform(0.0, 0.5, 40), rng.uniform(0.9, 1.2, 60), [5.0] * 20])
    for point in directions * scales[:, None]:
        triangle, found, bary = mirror.closest(point)
        points, _ = closest_on_triangles(point, corners[:, 0], corners[:, 1], corners[:, 2])
        exhaustive = np.sqrt(np.sum((points - point) ** 2, axis=1)).min()
        assert np.linalg.norm(found - point) == pytest.approx(exhaustive, rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(bary @ corners[triangle], found, atol=1e-12)


@pytest.mark.parametrize(("axis", "offset"), [("x", 0.0), ("y", 0.0), ("z", 0.0)])
def test_the_image_on_a_symmetric_sphere_is_the_reflection(axis: str, offset: float) -> None:
    mesh = uv_sphere(128, 64)  # symmetric about its three axis planes (as vertex sets)
    mirror = MeshMirror(mesh, MirrorPlane(axis, offset))
    k = "xyz".index(axis)
    rng = np.random.default_rng(1)
    for vertex in rng.integers(0, len(mesh.positions), 40):
        p = mesh.positions[vertex].astype(np.float64)
        n = mesh.normals[vertex].astype(np.float64)
        image = mirror.image(SurfaceHit(p, n, mesh.uvs[vertex].astype(np.float64)))
        want = p.copy()
        want[k] = -want[k]
        np.testing.assert_allclose(image.position, want, atol=1e-6)
        np.testing.assert_allclose(image.normal, want, atol=1e-5)  # a unit sphere's normal
        # its own uv: uv_sphere's longitude/latitude formula at the reflected point
        lon, lat = np.arctan2(want[0], want[2]), np.arcsin(np.clip(want[1], -1, 1))
        u, v = 0.5 + lon / (2 * np.pi), 0.5 + lat / np.pi
        if abs(want[1]) < 0.999 and min(u, 1 - u) > 1e-6:  # not a pole nor the seam
            np.testing.assert_allclose(image.uv, [u, v], atol=1e-6)


def test_an_offset_plane_moves_the_image_and_bad_planes_are_refused() -> None:
    mesh = uv_sphere(64, 32)
    plane = MirrorPlane("x", 0.25)
    np.testing.assert_allclose(plane.point(mesh), [0.25, 0.0, 0.0], atol=1e-6)
    through = plane.point(mesh)
    np.testing.assert_allclose(plane.reflect(np.array([0.9, 0.1, 0.2]), through), [-0.4, 0.1, 0.2])
    with pytest.raises(ValueError, match="mirror axis"):
        MirrorPlane("w")
    with pytest.raises(ValueError, match="finite"):
        MirrorPlane("x", float("nan"))
