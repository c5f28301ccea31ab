"""Viewport meshes without a GL context: loaders, computed tangents, the orbit camera.

Truth: the analytic sphere's frame (tangent = d/du of the longitude/latitude
parameterisation of :mod:`matshop.render.scenes`), the OBJ file's own vertices
for the glTF round trip, and the reference scene's ray directions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from matshop.render import scenes
from matshop.viewport.gl import mesh_data
from matshop.viewport.gl.camera import OrbitCamera

GEOMETRY = Path(__file__).resolve().parents[2] / "shared" / "data" / "geometry"


def test_computed_tangents_follow_increasing_u_on_the_sphere():
    sphere = mesh_data.uv_sphere(64, 32)
    computed = mesh_data.compute_tangents(
        sphere.positions, sphere.normals, sphere.uvs, sphere.indices.astype(np.int64)
    )
    away_from_poles = np.abs(sphere.positions[:, 1]) < 0.95
    cosine = np.sum(computed[away_from_poles, :3] * sphere.tangents[away_from_poles, :3], axis=1)
    print(f"worst cosine to the analytic tangent: {cosine.min():.5f}")
    assert cosine.min() > 0.998
    assert np.all(computed[away_from_poles, 3] == 1.0)  # right-handed: bitangent along +v


def test_mirrored_uvs_flip_the_handedness():
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
    normals = np.tile([0.0, 0.0, 1.0], (3, 1))
    indices = np.array([[0, 1, 2]])
    plain = mesh_data.compute_tangents(
        positions, normals, np.array([[0, 0], [1, 0], [0, 1.0]]), indices
    )
    mirrored = mesh_data.compute_tangents(
        positions, normals, np.array([[1, 0], [0, 0], [1, 1.0]]), indices
    )
    assert plain[0] == pytest.approx([1, 0, 0, 1])
    assert mirrored[0] == pytest.approx([-1, 0, 0, -1])


@pytest.mark.skipif(not GEOMETRY.is_dir(), reason="shared geometry not present")
def test_gltf_and_obj_give_the_same_mesh(tmp_path):
    pygltflib = pytest.importorskip("pygltflib")
    obj = mesh_data.load_mesh(GEOMETRY / "plane.obj", normalize=False)
    positions = obj.positions.astype(np.float32)
    uvs = obj.uvs.astype(np.float32).copy()
    uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's v runs down the image
    indices = obj.indices.astype(np.uint32)
    blob = positions.tobytes() + uvs.tobytes() + indices.tobytes()
    views = [
        (0, positions.nbytes),
        (positions.nbytes, uvs.nbytes),
        (positions.nbytes + uvs.nbytes, indices.nbytes),
    ]
    gltf = pygltflib.GLTF2(
        scenes=[pygltflib.Scene(nodes=[0])],
        nodes=[pygltflib.Node(mesh=0)],
        meshes=[
            pygltflib.Mesh(
                primitives=[
                    pygltflib.Primitive(
                        attributes=pygltflib.Attributes(POSITION=0, TEXCOORD_0=1), indices=2
                    )
                ]
            )
        ],
        accessors=[
            pygltflib.Accessor(
                bufferView=0,
                componentType=5126,
                count=len(positions),
                type="VEC3",
                min=positions.min(0).tolist(),
                max=positions.max(0).tolist(),
            ),
            pygltflib.Accessor(bufferView=1, componentType=5126, count=len(uvs), type="VEC2"),
            pygltflib.Accessor(bufferView=2, componentType=5125, count=indices.size, type="SCALAR"),
        ],
        bufferViews=[pygltflib.BufferView(buffer=0, byteOffset=o, byteLength=n) for o, n in views],
        buffers=[pygltflib.Buffer(byteLength=len(blob))],
    )
    gltf.set_binary_blob(blob)
    path = tmp_path / "plane.glb"
    gltf.save_binary(str(path))
    loaded = mesh_data.load_mesh(path, normalize=False)
    np.testing.assert_allclose(loaded.positions, obj.positions, atol=1e-6)
    np.testing.assert_allclose(loaded.uvs, obj.uvs, atol=1e-6)
    np.testing.assert_array_equal(loaded.indices, obj.indices)
    # no normals or tangents in the file: computed, facing the OBJ's normals
    assert np.all(np.sum(loaded.normals * obj.normals, axis=1) > 0.999)
    assert np.all(np.abs(np.sum(loaded.tangents[:, :3] * loaded.normals, axis=1)) < 1e-5)


def test_default_camera_is_the_reference_view():
    size = 32
    camera = OrbitCamera()
    origin, rays = scenes.camera_rays(size)
    np.testing.assert_allclose(camera.eye(), origin, atol=1e-12)
    for row, col in [(0, 0), (5, 20), (31, 31)]:
        np.testing.assert_allclose(
            camera.ray(col + 0.5, row + 0.5, size, size), rays[row, col], atol=1e-12
        )
    # projecting a point back lands on the pixel whose ray made it
    point = origin + 3.2 * rays[5, 20]
    assert camera.project(point, size, size) == pytest.approx([20.5, 5.5])
