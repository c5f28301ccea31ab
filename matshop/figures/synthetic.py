"""Synthetic test materials for the figures, where the shared data cannot show an effect.

Every figure that uses one of these says so in its caption and in
``docs/figures.md``. They are built from closed forms, so what they contain
is known exactly:

- :func:`steep_studs`: a height field of square studs (flat tops, planar walls
  at a chosen angle, flat ground between), for Fig. 2(a) on steep relief;
- :func:`phong_tiles`: glossy Phong tiles in rough Phong grout, for
  Fig. 2(b): unsharp masking a parameter as non-linear as a Phong exponent;
- :func:`with_anisotropy`: a real texture set given a tangent frame and an
  Ashikhmin-Shirley lobe derived from its GGX roughness, for Fig. 7(h).
"""

from __future__ import annotations

import numpy as np

from ..material import Material, Schema
from ..render.materials import from_maps
from ..spaces import get_space


def steep_studs(
    size: int = 256,
    *,
    period: int = 64,
    top: float = 10.0,
    foot: float = 26.0,
    wall_deg: float = 55.0,
) -> np.ndarray:
    """Height ``(size, size)`` in texel widths of a grid of square studs.

    Each ``period``-texel cell holds a frustum: flat top out to ``top`` texels
    from the cell centre (Chebyshev distance), walls rising at ``wall_deg``
    between ``top`` and ``foot``, flat ground beyond. The walls' normals tilt
    by exactly ``wall_deg`` (:func:`matshop.spaces.frame.height_to_normal`
    with strength 1).
    """
    c = (np.arange(size) + 0.5) % period - 0.5 * period
    x, y = np.meshgrid(c, c)
    r = np.maximum(np.abs(x), np.abs(y))
    return (np.clip(foot - r, 0.0, foot - top) * np.tan(np.radians(wall_deg))).astype(np.float32)


def tile_mask(size: int = 256, *, period: int = 64, grout: int = 8) -> np.ndarray:
    """``(size, size)`` bool, True on the tiles, False on the ``grout``-texel joints."""
    k = np.arange(size) % period
    line = (k >= grout // 2) & (k < period - grout // 2)
    return line[None, :] & line[:, None]


def phong_tiles(
    size: int = 256,
    *,
    period: int = 64,
    grout: int = 16,
    n_tile: float = 400.0,
    n_grout: float = 40.0,
) -> tuple[Material, np.ndarray]:
    """Glossy Phong tiles (exponent ``n_tile``) in rough grout (``n_grout``), and the tile mask.

    The paper's Fig. 2(b) edits Phong exponents; the bundled tile set holds
    GGX perceptual roughness, which is already nearly linear in highlight
    size, so it cannot show how a non-linear parameter misbehaves.
    """
    tiles = tile_mask(size, period=period, grout=grout)
    kd = np.where(tiles[..., None], [0.62, 0.36, 0.30], [0.55, 0.53, 0.50])
    n = np.where(tiles, n_tile, n_grout)
    material = from_maps(
        {
            "diffuse": kd.astype(np.float32),
            "specular": np.full((size, size, 3), 0.35, np.float32),
            "phong_exponent": n.astype(np.float32),
        },
        name="synthetic Phong tiles",
    )
    return material, tiles


def exponent_from_roughness(roughness: np.ndarray) -> np.ndarray:
    """The Phong exponent whose lobe has the median angle of the GGX lobe ``alpha = r^2``.

    GGX's median half-vector angle is ``atan(alpha)``; the Ashikhmin-Shirley
    space's default coordinate *is* the median angle, so the exponent is that
    space's ``from_edit(atan(alpha))`` -- an isotropic lobe of the same
    highlight size.
    """
    alpha = np.clip(np.asarray(roughness, dtype=np.float32), 0.0, 1.0) ** 2
    return get_space("phong").from_edit(np.arctan(alpha).astype(np.float32))


def with_anisotropy(material: Material, *, tangent_deg: float = 60.0) -> Material:
    """``material`` with a constant tangent field and an isotropic Ashikhmin-Shirley lobe.

    - ``normal`` becomes the 6-channel frame ``(n, t)`` (space
      ``normal_tangent``): the tangent is the texture's ``u`` axis rotated by
      ``tangent_deg`` about the normal map's normal (Gram-Schmidt against it);
    - ``roughness`` is replaced by ``anisotropic_exponents`` ``(nu, nv)``, both
      :func:`exponent_from_roughness` -- isotropic until an edit scales one axis.
    """
    maps = dict(material.maps)
    h, w = material.size
    n = maps.get("normal", np.broadcast_to(np.float32([0, 0, 1]), (h, w, 3)))[..., :3]
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    a = np.radians(tangent_deg)
    t = np.broadcast_to(np.float32([np.cos(a), np.sin(a), 0.0]), n.shape)
    t = t - np.sum(t * n, axis=-1, keepdims=True) * n
    t = t / np.linalg.norm(t, axis=-1, keepdims=True)
    maps["normal"] = np.concatenate([n, t], axis=-1).astype(np.float32)
    exponent = exponent_from_roughness(maps.pop("roughness", np.full((h, w, 1), 0.5)))
    maps["anisotropic_exponents"] = np.concatenate([exponent, exponent], axis=-1)
    spaces = {p.name: p.space.name for p in material.schema.parameters if p.name in maps}
    spaces["normal"] = "normal_tangent"
    spaces.pop("roughness", None)
    schema = Schema.from_names(list(maps), spaces)
    return Material(f"{material.name} + tangent frame + AS lobe", schema, maps, material.sources)


#: lobe parameters :func:`with_lobe` can give a material
LOBES = ("ggx", "beckmann", "phong", "ashikhmin_shirley", "sampled", "sampled_two_lobe")


def with_lobe(material: Material, family: str, *, stretch: float = 2.5) -> Material:
    """``material`` with its GGX roughness re-expressed as another D of the same highlight size.

    Each texel's lobe keeps the GGX lobe's median angle ``atan(r^2)``:
    Beckmann ``m = r^2 / sqrt(ln 2)``, Phong :func:`exponent_from_roughness`,
    Ashikhmin-Shirley :func:`with_anisotropy` with the tangent axis's edit
    value scaled by ``stretch`` (so the lobe is really anisotropic), sampled:
    the GGX lobe tabulated (``d_from_ggx``). ``sampled_two_lobe`` tabulates a
    shape no analytic family has: 70% GGX ``alpha`` plus 30% GGX ``4 alpha``.
    For tests of renderers against each other, not for looks.
    """
    from ..spaces.sampled import d_from_ggx

    if family not in LOBES:
        raise ValueError(f"unknown lobe {family!r} (use one of {', '.join(LOBES)})")
    if family == "ggx":
        return material
    if family == "ashikhmin_shirley":
        aniso = with_anisotropy(material)
        edit = aniso.to_edit()
        data = edit.data.copy()
        data[..., edit.schema.edit_slices["anisotropic_exponents"].start] *= np.float32(stretch)
        return type(edit)(edit.name, edit.schema, data, edit.sources).to_physical()
    maps = dict(material.maps)
    r = maps.pop("roughness")
    alpha = np.clip(r.astype(np.float64), 0.0, 1.0) ** 2
    if family == "beckmann":
        name, value = "beckmann_roughness", alpha / np.sqrt(np.log(2.0))
    elif family == "phong":
        name, value = "phong_exponent", exponent_from_roughness(r)
    else:
        a = np.clip(alpha[..., 0], 1e-3, 1.0)
        table = d_from_ggx(a)
        if family == "sampled_two_lobe":
            table = 0.7 * table + 0.3 * d_from_ggx(np.minimum(4.0 * a, 1.0))
        name, value = "distribution", table
    maps[name] = np.asarray(value, dtype=np.float32)
    spaces = {p.name: p.space.name for p in material.schema.parameters if p.name in maps}
    return Material(f"{material.name} ({family})", Schema.from_names(list(maps), spaces), maps)
