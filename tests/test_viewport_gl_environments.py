"""Every lighting choice drawn by the OpenGL viewport against the reference renderer.

For each preset (studio, sky, uniform) and an artist's HDR written here (turned 90
degrees, +1 stop), the viewport's frame of the bundled sample on the sphere is compared
per pixel, in 8-bit display codes, with :func:`matshop.render.render.render` of the same
material, environment (the choice's :meth:`EnvironmentChoice.load`), samples and exposure.
Tolerances are the viewport's (``tests/test_viewport_gl.py``: mean <= 0.4 code, 99th
percentile <= 3 codes over the sphere), measured per choice and printed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gl_testing import require_gl

require_gl()  # skips the module, saying why, without pytest-qt or an OpenGL 3.3 context

from gl_testing import release, shown_viewport  # noqa: E402
from lighting_truth import artists_hdr  # noqa: E402

from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import Document  # noqa: E402
from matshop.render import scenes  # noqa: E402
from matshop.render.environment_choice import EnvironmentChoice  # noqa: E402
from matshop.render.render import render  # noqa: E402
from matshop.render.surface import prefilter_factor  # noqa: E402
from matshop.render.tonemap import to_uint8  # noqa: E402
from matshop.viewport.gl import mesh_data  # noqa: E402

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"
SIZE = 160
SAMPLES = 16
MEAN_TOLERANCE = 0.4
P99_TOLERANCE = 3.0


@pytest.fixture(scope="module")
def material():
    loaded, _ = load_material(SAMPLE)
    return loaded


@pytest.mark.parametrize("name", ["studio", "sky", "uniform", "hdr turned 90, +1 stop"])
def test_each_lighting_choice_matches_the_reference(gl_context, qtbot, material, tmp_path, name):
    if name.startswith("hdr"):
        choice = EnvironmentChoice.parse(artists_hdr(tmp_path / "room.exr"), 90.0, 1.0)
    else:
        choice = EnvironmentChoice.parse(name)
    environment = choice.load()
    image = render(material, size=SIZE, samples=SAMPLES, environment=environment)
    reference = to_uint8(image.display(exposure=choice.exposure_stops)[..., :3])

    viewport = shown_viewport(qtbot, SIZE)
    try:
        viewport.set_environment(environment)
        viewport.set_document(Document.from_material(material))
        viewport.set_uv_scale(2.0, 1.0)  # the reference sphere's tiles
        viewport.set_mesh(mesh_data.uv_sphere())
        viewport.lighting.samples = SAMPLES
        viewport.lighting.exposure = choice.exposure_stops
        uv_per_pixel = scenes.sphere(SIZE).uv_per_pixel
        viewport.lighting.texture_lod = float(
            np.log2(prefilter_factor(material.size, uv_per_pixel))
        )
        gl = viewport.render_image(SIZE)[..., :3]
    finally:
        release(viewport)

    mask = scenes.sphere(SIZE).mask
    diff = np.abs(gl.astype(int) - reference.astype(int)).max(axis=2)
    on = diff[mask]
    mean, p99 = float(on.mean()), float(np.percentile(on, 99))
    print(
        f"{name}: GL vs reference mean {mean:.3f}, p99 {p99:.1f}, max {on.max()} codes on "
        f"the sphere; background max {diff[~mask].max()}"
    )
    assert mean <= MEAN_TOLERANCE and p99 <= P99_TOLERANCE
    assert diff[~mask].max() <= 1
