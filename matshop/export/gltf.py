"""glTF 2.0 binary (``.glb``): the material on a mesh, textures embedded.

The textures are the built-in ``gltf`` preset's (baseColor sRGB, OpenGL
normal, one occlusionRoughnessMetallic PNG serving both the occlusion and
the metallicRoughness slot), packed and quantised exactly as the texture
export does, so a ``.glb`` written beside a ``gltf`` export holds the same
pixels. Whatever preset the files use, the ``.glb`` follows glTF's rules.

``TANGENT`` (MikkTSpace's, :mod:`matshop.render.tangent_space`, what normal
maps are baked against) is written whenever the material has a normal map or
anisotropy: runtime-generated tangents are not portable across viewers (the
validator warns). Only images the material reads are embedded: without a
normal map there is no flat normal image. An anisotropic material (Ashikhmin–Shirley exponents) gets
``KHR_materials_anisotropy``: strength and direction from the two
exponents, via the Beckmann/Phong correspondence ``alpha = sqrt(2 / (n + 2))``
and glTF's ``alpha_t = mix(alpha_b, 1, strength^2)``.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pygltflib as gl

from ..io.images import write_image
from ..material import Material
from .obj import Mesh, tangents
from .pack import has_parameter, pack_output
from .presets import OutputSpec, load_preset
from .quantize import quantize

_ANISOTROPY = "KHR_materials_anisotropy"
_REPEAT = 10497
_LINEAR = 9729
_LINEAR_MIPMAP_LINEAR = 9987


class _Blob:
    """The binary chunk: bufferViews appended 4-byte aligned."""

    def __init__(self, doc: gl.GLTF2) -> None:
        self.doc = doc
        self.data = bytearray()

    def view(self, payload: bytes, target: int | None = None, stride: int | None = None) -> int:
        self.data.extend(b"\0" * (-len(self.data) % 4))
        self.doc.bufferViews.append(
            gl.BufferView(
                buffer=0,
                byteOffset=len(self.data),
                byteLength=len(payload),
                target=target,
                byteStride=stride,
            )
        )
        self.data.extend(payload)
        return len(self.doc.bufferViews) - 1

    def accessor(self, array: np.ndarray, kind: str, target: int, bounds: bool = False) -> int:
        component = gl.UNSIGNED_INT if array.dtype == np.uint32 else gl.FLOAT
        view = self.view(np.ascontiguousarray(array).tobytes(), target)
        accessor = gl.Accessor(
            bufferView=view, componentType=component, count=len(array), type=kind
        )
        if bounds:
            accessor.min = array.min(axis=0).astype(float).tolist()
            accessor.max = array.max(axis=0).astype(float).tolist()
        self.doc.accessors.append(accessor)
        return len(self.doc.accessors) - 1


def anisotropy_texture(material: Material) -> np.ndarray:
    """``(H, W, 3)`` KHR_materials_anisotropy texels: RG direction in [0, 1], B strength.

    The direction is the axis with the wider lobe (larger alpha), in tangent
    space: the material's tangent map when it has one, else ``+u``.
    """
    exponents = material.maps["anisotropic_exponents"].astype(np.float64)
    alpha = np.sqrt(2.0 / (np.maximum(exponents, 0.0) + 2.0))
    a_u, a_v = alpha[..., 0], alpha[..., 1]
    a_t, a_b = np.maximum(a_u, a_v), np.minimum(a_u, a_v)
    strength = np.sqrt(np.clip((a_t - a_b) / np.maximum(1.0 - a_b, 1e-9), 0.0, 1.0))
    if has_parameter(material, "tangent"):
        t = material.maps["normal"][..., 3:5].astype(np.float64)
    else:
        t = np.zeros(a_u.shape + (2,))
        t[..., 0] = 1.0
    t /= np.maximum(np.linalg.norm(t, axis=-1, keepdims=True), 1e-12)
    along_v = (a_v > a_u)[..., None]
    direction = np.where(along_v, np.stack([-t[..., 1], t[..., 0]], axis=-1), t)
    return np.concatenate([0.5 * direction + 0.5, strength[..., None]], axis=-1).astype(np.float32)


def build_glb(
    material: Material,
    name: str,
    mesh: Mesh,
    images: dict[str, bytes],
) -> gl.GLTF2:
    """The glTF document with ``images`` (PNG bytes by role) embedded."""
    doc = gl.GLTF2(asset=gl.Asset(version="2.0", generator="matshop"))
    blob = _Blob(doc)
    attributes = gl.Attributes(
        POSITION=blob.accessor(mesh.positions, gl.VEC3, gl.ARRAY_BUFFER, bounds=True),
        NORMAL=blob.accessor(mesh.normals, gl.VEC3, gl.ARRAY_BUFFER),
        TEXCOORD_0=blob.accessor(mesh.uvs, gl.VEC2, gl.ARRAY_BUFFER),
    )
    if "normal" in images or "anisotropy" in images:  # mapped frames need the mesh's tangents
        attributes.TANGENT = blob.accessor(tangents(mesh), gl.VEC4, gl.ARRAY_BUFFER)
    indices = blob.accessor(mesh.indices, gl.SCALAR, gl.ELEMENT_ARRAY_BUFFER)
    doc.samplers.append(
        gl.Sampler(magFilter=_LINEAR, minFilter=_LINEAR_MIPMAP_LINEAR, wrapS=_REPEAT, wrapT=_REPEAT)
    )
    texture: dict[str, int] = {}
    for role, png in images.items():
        doc.images.append(
            gl.Image(bufferView=blob.view(png), mimeType="image/png", name=f"{name}_{role}")
        )
        doc.textures.append(gl.Texture(sampler=0, source=len(doc.images) - 1))
        texture[role] = len(doc.textures) - 1

    pbr = gl.PbrMetallicRoughness(
        baseColorTexture=gl.TextureInfo(index=texture["baseColor"]),
        metallicRoughnessTexture=gl.TextureInfo(index=texture["occlusionRoughnessMetallic"]),
        metallicFactor=1.0,
        roughnessFactor=1.0,
    )
    mat = gl.Material(name=name, pbrMetallicRoughness=pbr, doubleSided=False)
    if has_parameter(material, "normal"):
        mat.normalTexture = gl.NormalMaterialTexture(index=texture["normal"])
    if has_parameter(material, "ao"):
        mat.occlusionTexture = gl.OcclusionTextureInfo(index=texture["occlusionRoughnessMetallic"])
    if "emissive" in texture:
        mat.emissiveTexture = gl.TextureInfo(index=texture["emissive"])
        mat.emissiveFactor = [1.0, 1.0, 1.0]
    if "anisotropy" in texture:
        mat.extensions[_ANISOTROPY] = {
            "anisotropyStrength": 1.0,
            "anisotropyTexture": {"index": texture["anisotropy"]},
        }
        doc.extensionsUsed.append(_ANISOTROPY)
    doc.materials.append(mat)
    doc.meshes.append(
        gl.Mesh(
            name=name,
            primitives=[gl.Primitive(attributes=attributes, indices=indices, material=0)],
        )
    )
    doc.nodes.append(gl.Node(mesh=0, name=name))
    doc.scenes.append(gl.Scene(nodes=[0]))
    doc.scene = 0
    doc.buffers.append(gl.Buffer(byteLength=len(blob.data)))
    doc.set_binary_blob(bytes(blob.data))
    return doc


def _png_bytes(array: np.ndarray, scratch: Path, *, seed: int, dither: bool = True) -> bytes:
    """Quantise like the texture export and encode one 8-bit PNG in memory."""
    codes = quantize(array, "uint8", dither=dither, seed=seed)
    write_image(scratch, codes, bit_depth="uint8")
    try:
        return scratch.read_bytes()
    finally:
        scratch.unlink()


def _referenced(material: Material, output: OutputSpec) -> bool:
    """Whether :func:`build_glb` references ``output``'s image: an optional map or
    the normal map only when the material has their parameter (no unused images)."""
    if output.optional or output.source == "normal":
        return any(has_parameter(material, s) for s in output.sources)
    return True


def glb_writer(
    material: Material, name: str, geometry: Mesh, *, seed: int = 0
) -> Callable[[Path], None]:
    """A writer (for :mod:`matshop.io.fileset`) of ``material`` as a ``.glb`` on ``geometry``."""

    def write(path: Path) -> None:
        preset = load_preset("gltf")
        images: dict[str, bytes] = {}
        for output in preset.outputs:
            if not _referenced(material, output):
                continue
            scratch = path.with_name(f".{path.stem}-{output.channel}.png")
            channel_seed = zlib.crc32(f"{seed}:{output.channel}".encode())
            images[output.channel] = _png_bytes(
                pack_output(material, output, preset),
                scratch,
                seed=channel_seed,
                dither=output.dithering,
            )
        if has_parameter(material, "anisotropic_exponents"):
            scratch = path.with_name(f".{path.stem}-anisotropy.png")
            images["anisotropy"] = _png_bytes(anisotropy_texture(material), scratch, seed=seed)
        build_glb(material, name, geometry, images).save_binary(str(path))

    return write
