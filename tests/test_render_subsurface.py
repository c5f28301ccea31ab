"""The texture-space SubEdit BSSRDF: energy and the effect of scaling radii.

Truth: a uniform profile of albedo A under uniform light reflects like a
Lambertian of albedo A (times the Fresnel transmissions, computed here from
Schlick's formula); scaling the radii spreads light (less contrast) without
changing the total reflected energy.
"""

from __future__ import annotations

import numpy as np
import pytest

from matshop.render import environment
from matshop.render.integrator import DirectionalLight
from matshop.render.materials import constant, from_maps
from matshop.render.render import render
from matshop.render.subsurface import ring_kernels
from matshop.spaces.subsurface import profile_exponential, radius_measure


def test_ring_kernels_carry_the_exact_bin_measure():
    kernels = ring_kernels(32, 1.0, 1.0 / 12.0)
    np.testing.assert_allclose(kernels.sum(axis=(1, 2)), radius_measure(32, 1.0), rtol=1e-12)


def test_uniform_profile_in_uniform_light_reflects_its_albedo():
    albedo, ks = 0.7, 0.04
    material = constant(base_color=(1.0, 1.0, 1.0), profile=profile_exponential(albedo, 0.1))
    image = render(
        material, scene="swatch", size=16, environment=environment.uniform(1.0), specular=False
    )
    fi = 1.0 - ks - (1.0 - ks) / 21.0  # diffuse-averaged Schlick transmission
    fo = 1.0 - ks  # seen at normal incidence
    np.testing.assert_allclose(image.radiance, albedo * fi * fo, rtol=2e-3)


def test_scaling_radii_spreads_light_and_keeps_energy():
    size = 64
    rows, cols = np.mgrid[0:size, 0:size]
    normal = np.zeros((size, size, 3), np.float32)
    normal[..., 2] = 1.0
    normal[(cols // 8) % 2 == 0] = (0.6, 0.0, 0.8)  # lit and unlit stripes
    light = (DirectionalLight((1.0, 0.0, 1.0), (3.0, 3.0, 3.0)),)
    stats = []
    for length in (0.02, 0.2):
        profile = np.broadcast_to(profile_exponential(0.8, length), (size, size, 32))
        material = from_maps(
            {"base_color": np.ones((size, size, 3)), "profile": profile.copy(), "normal": normal}
        )
        image = render(
            material, scene="swatch", size=size, environment_scale=0.0, lights=light, specular=False
        )
        stats.append((image.radiance.mean(), image.radiance[..., 0].std()))
    (mean_sharp, std_sharp), (mean_wide, std_wide) = stats
    assert mean_wide == pytest.approx(mean_sharp, rel=0.03)
    assert std_wide < 0.5 * std_sharp
