"""Schemas lay parameters side by side; containers convert losslessly and in bands."""

from __future__ import annotations

import numpy as np
import pytest

from matshop import material as material_module
from matshop.material import Material, Schema


def _material(height: int = 5, width: int = 4) -> Material:
    rng = np.random.default_rng(0)
    schema = Schema.from_names(["base_color", "roughness", "normal", "metallic"])
    normal = rng.normal(size=(height, width, 3)) * [0.3, 0.3, 1] + [0, 0, 1]
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    maps = {
        "base_color": rng.random((height, width, 3), dtype=np.float32),
        "roughness": rng.random((height, width, 1), dtype=np.float32),
        "normal": normal.astype(np.float32),
        "metallic": rng.random((height, width, 1), dtype=np.float32),
    }
    return Material("test", schema, maps)


def test_edit_vector_is_the_concatenation_of_every_parameter() -> None:
    mat = _material()
    schema = mat.schema
    assert schema.edit_width == 3 + 1 + 3 + 1
    assert schema.edit_slices == {
        "base_color": slice(0, 3),
        "roughness": slice(3, 4),
        "normal": slice(4, 7),
        "metallic": slice(7, 8),
    }
    edit = mat.to_edit()
    for param in schema.parameters:
        expected = param.space.to_edit(mat.maps[param.name])
        assert np.array_equal(edit[param.name], expected)
    assert list(schema.channel_indices(["normal", "metallic"])) == [4, 5, 6, 7]


def test_banded_conversion_equals_one_shot(monkeypatch: pytest.MonkeyPatch) -> None:
    mat = _material(height=37, width=11)
    whole = mat.to_edit().data
    monkeypatch.setattr(material_module, "_BAND_TEXELS", 16)  # many tiny bands
    progress = []
    banded = mat.to_edit(progress=lambda d, t: progress.append((d, t)))
    assert np.array_equal(banded.data, whole)
    assert progress[-1][0] == progress[-1][1] > 1
    back_whole = banded.to_physical()
    for name in mat.schema.names:
        assert np.allclose(back_whole.maps[name], mat.maps[name], atol=2e-5)


def test_mismatched_maps_are_refused_with_the_parameter_named() -> None:
    mat = _material()
    maps = dict(mat.maps)
    maps["metallic"] = np.zeros((5, 5, 1), dtype=np.float32)
    with pytest.raises(ValueError, match="differ in size"):
        Material("bad", mat.schema, maps)
    maps = dict(mat.maps)
    maps["roughness"] = np.zeros((5, 4, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="roughness"):
        Material("bad", mat.schema, maps)


def test_space_overrides_and_unknown_names() -> None:
    schema = Schema.from_names(["roughness"], {"roughness": "ggx_alpha"})
    assert schema["roughness"].space.name == "ggx_alpha"
    with pytest.raises(KeyError, match="unknown editing space"):
        Schema.from_names(["roughness"], {"roughness": "nope"})
    with pytest.raises(KeyError, match="unknown parameter"):
        Schema.from_names(["sparkle"])


def test_one_pass_conversion_equals_each_space_alone() -> None:
    """Spaces that are one kernel step convert together (``_kernels.run_steps``); the
    result must be each space's own conversion, bit for bit, in both directions --
    with every kind of step (one to six channels) and maps that are strided views
    or float64."""
    rng = np.random.default_rng(3)
    height, width = 23, 17
    names = [
        "base_color", "emissive", "metallic", "roughness", "normal", "tangent", "lobe",
        "anisotropic_exponents",
    ]  # fmt: skip
    spaces = {
        "emissive": "gamma22",
        "roughness": "ggx_alpha",
        "tangent": "normal_tangent",
        "lobe": "phong",
        "metallic": "identity",
    }
    schema = Schema([Schema.from_names([n], spaces).parameters[0] for n in names])
    wide = rng.random((height, width, 6), dtype=np.float32) * 1.2 - 0.1  # outside [0, 1] too
    frame = rng.normal(size=(height, width, 6)).astype(np.float32)
    maps = {
        "base_color": wide[..., ::2],  # a strided view
        "emissive": wide[..., 3:].astype(np.float64),  # converted on the way in
        "metallic": wide[..., 1:2],
        "roughness": rng.random((height, width, 1), dtype=np.float32),
        "normal": frame[..., :3],
        "tangent": frame,
        "lobe": rng.uniform(0.0, 1e4, (height, width, 1)).astype(np.float32),
        # two channels (nu, nv), a strided view: the loops for two-channel rows
        "anisotropic_exponents": rng.uniform(0.0, 1e4, (height, width, 4)).astype(np.float32)[
            ..., 1:3
        ],
    }
    mat = Material("steps", schema, maps)
    edit = mat.to_edit()
    for param in schema.parameters:
        assert param.space.to_edit_step() is not None
        want = param.space.to_edit(maps[param.name])
        assert np.array_equal(edit[param.name], want, equal_nan=True), param.name
    edited = edit.data * np.float32(1.3)  # push values past the clamps on the way back
    back = material_module.EditMaterial("e", schema, edited).to_physical()
    for param in schema.parameters:
        want = param.space.from_edit(edited[..., schema.edit_slices[param.name]])
        assert np.array_equal(back.maps[param.name], want, equal_nan=True), param.name


def test_physical_maps_reuse_the_memory_an_edit_array_of_the_same_bytes_left() -> None:
    """The maps are C-contiguous, each what its space's own ``from_edit`` gives, and
    they lie in one pooled buffer: at 2K (above the pool's minimum) the memory of an
    edit array dropped just before is reused, not mapped anew."""
    mat = _material(height=512, width=512)  # 8 MB of edit values
    edit = mat.to_edit()
    blurred = type(edit)(edit.name, edit.schema, edit.data.copy(), edit.sources)
    left = edit.data.__array_interface__["data"][0]
    del edit
    back = blurred.to_physical()
    starts = []
    for param in mat.schema.parameters:
        got = back.maps[param.name]
        assert got.flags.c_contiguous and got.shape == (512, 512, param.phys_channels)
        assert np.array_equal(got, param.space.from_edit(blurred[param.name]))
        starts.append(got.__array_interface__["data"][0])
    assert min(starts) == left
