"""The renderer's front door: a material, a scene, lighting -> a linear image.

    from matshop.render import render
    image = render.render(material, scene="sphere", size=256)
    pixels = image.display()              # tone-mapped, sRGB, (H, W, 4) RGBA

``render`` builds the scene's geometry buffer, prepares the material's
shading inputs for that view, shades every covered pixel
(:mod:`matshop.render.integrator`), adds the SubEdit subsurface term when the
material has profiles, and fills the rest with the environment (or a flat
colour).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..errors import MatshopError
from ..material import Material
from . import scenes
from .environment import Environment, load_environment
from .integrator import DirectionalLight, Lighting, ProgressCallback, shade
from .surface import prepare
from .tonemap import to_display

SCENES = ("sphere", "swatch")


@dataclass
class RenderedImage:
    """Linear radiance ``(H, W, 3)`` and coverage ``(H, W)`` of one render."""

    radiance: np.ndarray
    alpha: np.ndarray

    def display(self, *, exposure: float = 0.0, tonemap: str = "aces") -> np.ndarray:
        """``(H, W, 4)`` float32 RGBA in [0, 1]: tone-mapped, sRGB-encoded color and coverage."""
        rgb = to_display(self.radiance, exposure=exposure, tonemap=tonemap)
        return np.concatenate([rgb, self.alpha[..., None].astype(np.float32)], axis=2)


def geometry(scene: str | os.PathLike[str], size: int, **options) -> scenes.GBuffer:
    """The geometry buffer of ``scene``: ``"sphere"``, ``"swatch"`` or a path to an OBJ mesh."""
    text = os.fspath(scene)
    if text == "sphere":
        return scenes.sphere(size, **options)
    if text == "swatch":
        return scenes.swatch(size, **options)
    if text.lower().endswith(".obj"):
        from .mesh import load_obj, mesh_gbuffer

        return mesh_gbuffer(load_obj(text), size, **options)
    raise MatshopError(f"unknown scene {text!r}: use sphere, swatch or a .obj mesh")


def render(
    material: Material,
    *,
    scene: str | os.PathLike[str] | scenes.GBuffer = "sphere",
    size: int = 256,
    environment: Environment | str | os.PathLike[str] | None = None,
    lights: tuple[DirectionalLight, ...] = (),
    samples: int = 16,
    background: str | tuple[float, float, float] = "environment",
    environment_scale: float = 1.0,
    specular: bool = True,
    texel_size: float | None = None,
    progress: ProgressCallback | None = None,
    scene_options: dict | None = None,
) -> RenderedImage:
    """Render ``material`` and return linear radiance.

    Parameters
    ----------
    material : Material
        Physical maps (what :func:`matshop.io.material_io.load_material` returns).
    scene : "sphere", "swatch", a path to an .obj, or a prepared GBuffer.
    size : int
        Image width and height in pixels (swatch: the texture is resampled to it).
    environment : Environment, "studio", "sky", "uniform", a .hdr/.exr path, or None
        (the studio). Pass ``environment_scale=0`` for directional lights only.
    lights : directional lights added to the environment.
    samples : int
        Specular samples per pixel for the environment (16 is thumbnail quality).
    specular : False renders the diffuse term alone.
    background : "environment" (the blurred environment behind the object) or an RGB triple.
    texel_size : float, optional
        Length of one texel in the subsurface profiles' unit (default: 1/16 of
        the profile's ``r_max``); only used when the material has profiles.
    progress : called with (chunks done, chunks total).
    scene_options : extra keyword arguments for the scene (``tiles``, ``tilt_deg``).
    """
    if size < 1 or samples < 1:
        raise MatshopError(f"size and samples must be positive (got {size}, {samples})")
    env = (
        environment
        if isinstance(environment, Environment) or environment is None and environment_scale == 0
        else load_environment(environment)
    )
    gbuf = (
        scene
        if isinstance(scene, scenes.GBuffer)
        else geometry(scene, size, **(scene_options or {}))
    )
    maps = prepare(material, uv_per_pixel=gbuf.uv_per_pixel)
    lighting = Lighting(
        env, tuple(lights), samples, environment_scale=environment_scale, specular=specular
    )
    diffuse = None
    if maps.profile is not None:
        from .subsurface import subsurface_radiance

        diffuse = subsurface_radiance(gbuf, maps, lighting, texel_size=texel_size)
    values = shade(gbuf, maps, lighting, progress=progress, diffuse_override=diffuse)
    h, w = gbuf.shape
    radiance = np.empty((h, w, 3), dtype=np.float32)
    if isinstance(background, str):
        if background != "environment":
            raise MatshopError(
                f"background must be 'environment' or an RGB triple, got {background!r}"
            )
        if gbuf.rays is not None and env is not None:
            r = gbuf.rays
            radiance[:] = env.lookup(r[..., 0], r[..., 1], r[..., 2], 2.0)
        else:
            radiance[:] = 0.0
    else:
        radiance[:] = np.asarray(background, dtype=np.float32)
    radiance[gbuf.mask] = values
    return RenderedImage(radiance, gbuf.mask.astype(np.float32))
