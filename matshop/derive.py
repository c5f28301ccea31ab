"""Parameters derived from others, so real data exists for every space.

No engine format stores a sampled microfacet distribution, so matshop makes
one from the analytic roughness an artist already has: GGX perceptual
roughness ``r`` gives ``alpha = r**2`` and the GGX lobe sampled in 128 bins.
"""

from __future__ import annotations

import numpy as np

from .errors import MatshopError
from .material import Material, Parameter, Schema
from .spaces import get_space
from .spaces.sampled import d_from_ggx

#: GGX with alpha -> 0 is a Dirac lobe that no 128-bin table can hold; this
#: floor keeps the narrowest lobe resolvable (about 3 bins wide).
MIN_ALPHA = 0.02


def with_sampled_distribution(material: Material) -> Material:
    """Replace ``roughness`` (GGX perceptual) by a sampled ``distribution``."""
    if "roughness" not in material.schema:
        raise MatshopError(
            f"material {material.name!r} has no roughness map to derive a distribution from"
        )
    roughness = material.maps["roughness"][..., 0]
    alpha = np.clip(roughness.astype(np.float64) ** 2, MIN_ALPHA, 1.0)
    space = get_space("sampled")
    distribution = d_from_ggx(alpha, n=space.phys_channels)
    params = [
        Parameter("distribution", space) if p.name == "roughness" else p
        for p in material.schema.parameters
    ]
    maps = {k: v for k, v in material.maps.items() if k != "roughness"}
    maps["distribution"] = distribution
    sources = {k: v for k, v in material.sources.items() if k != "roughness"}
    sources["distribution"] = {
        "derived_from": material.sources.get("roughness", {}).get("file", "roughness"),
        "bit_depth": "half",
    }
    return Material(material.name, Schema(params), maps, sources)
