"""The OpenGL viewport against the reference renderer for every D, not only GGX.

Same comparison as ``tests/test_viewport_gl.py`` (8-bit display values over
the sphere, same view, environment, light, samples, texture level), on the
chessboard set (512^2) with its GGX roughness re-expressed per texel as
Beckmann, Phong, an anisotropic Ashikhmin-Shirley lobe with a tangent frame,
and tabulated (sampled) lobes (:func:`matshop.figures.synthetic.with_lobe`:
each keeps the GGX lobe's median angle). For each, a deliberately wrong
lobe -- another family, or the anisotropic axes swapped -- must fail the
tolerance.

Run under ``xvfb-run -a``; skips, saying why, only without an OpenGL 3.3 context.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("PySide6.QtOpenGLWidgets", reason="PySide6 (extra 'gui') not installed")
pytest.importorskip("OpenGL.GL", reason="PyOpenGL (extra 'gui') not installed")

from matshop.viewport.gl.context import (  # noqa: E402
    install_default_format,
    no_display_reason,
)

install_default_format()

if no_display_reason() is not None:  # before pytest-qt starts Qt
    pytest.skip(no_display_reason(), allow_module_level=True)

from gl_testing import shown_viewport  # noqa: E402

from matshop.figures.common import resized  # noqa: E402
from matshop.figures.synthetic import with_lobe  # noqa: E402
from matshop.io.material_io import load_material  # noqa: E402
from matshop.layers import Document  # noqa: E402
from matshop.material import Material  # noqa: E402
from matshop.render import scenes  # noqa: E402
from matshop.render.integrator import DirectionalLight  # noqa: E402
from matshop.render.render import render  # noqa: E402
from matshop.render.surface import prefilter_factor  # noqa: E402
from matshop.render.tonemap import to_uint8  # noqa: E402
from matshop.viewport.gl import mesh_data  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CHESSBOARD = ROOT.parent / "shared" / "data" / "chessboard"
SAMPLE = ROOT / "resources" / "sample"
OUT = ROOT / "test-output"
SIZE = 256
SAMPLES = 16
LIGHT = DirectionalLight((-0.5, 0.7, 0.6), (2.0, 2.0, 2.0))

# Tolerances, from measurement (llvmpipe, chessboard at 512^2, 256^2 view, 16 samples,
# studio + one light; the tests print them), in 8-bit display values over the sphere:
#   right lobe:  ggx mean 0.20 p99 2 (test_viewport_gl.py) | beckmann 0.20 / 2 |
#                phong 0.20 / 2 | ashikhmin_shirley (tangent frame) 0.20 / 2
#   wrong lobe:  beckmann shown as GGX 3.8 / 16 | phong shown as GGX 3.8 / 16 |
#                AS shown as Phong 5.0 / 29 | AS with nu and nv swapped 5.1 / 42
# (Phong shown as its Beckmann equivalent, n = 2 / m^2 - 2, measures 0.26 / 2: the two
# are indistinguishable at these exponents, so it is not used as the wrong lobe.)
# The analytic families share the GGX test's bounds, which sit between the two groups.
MEAN_TOLERANCE = 0.4
P99_TOLERANCE = 3.0
# Sampled lobes (chessboard at 256^2, read at level 0 by both): the GPU reads D from a
# 16-level inverse-CDF lookup (shading_maps), the reference from the 128-bin table:
#   GGX table: lookup 0.52 / 3 (both read D mass-exactly and without steps: the
#   reference linear in sin^2 inside each of its 128 bins, the GPU inside each of its
#   17 segments, with a power-law tail);
#   two-lobe table (70% GGX alpha + 30% GGX 4 alpha): lookup 0.45 / 2, while the old
#   stand-in, the GGX lobe of the same median angle, measures 2.1 / 10.
SAMPLED_MEAN_TOLERANCE = 0.8
SAMPLED_P99_TOLERANCE = 4.0


@pytest.fixture
def viewport(gl_context, qtbot):
    return shown_viewport(qtbot, SIZE)


@pytest.fixture(scope="module", params=["sample", "chessboard"])
def base(request):
    if request.param == "chessboard" and not CHESSBOARD.is_dir():
        pytest.skip(f"{CHESSBOARD} not present (the shared data folder)")
    loaded, _ = load_material(SAMPLE if request.param == "sample" else CHESSBOARD)
    return resized(loaded, 512)


def _reference(material: Material) -> np.ndarray:
    image = render(material, size=SIZE, samples=SAMPLES, lights=(LIGHT,))
    return to_uint8(image.display()[..., :3])


def _lod(material: Material) -> float:
    return float(np.log2(prefilter_factor(material.size, scenes.sphere(SIZE).uv_per_pixel)))


def _gl(viewport, material: Material, *, lobe: str | None = None) -> np.ndarray:
    viewport.set_document(Document.from_material(material))
    viewport.set_uv_scale(2.0, 1.0)
    viewport.set_mesh(mesh_data.uv_sphere())
    viewport.set_lobe(lobe)
    viewport.lighting.samples = SAMPLES
    viewport.lighting.lights = (LIGHT,)
    viewport.lighting.texture_lod = _lod(material)
    return viewport.render_image(SIZE)[..., :3]


def _errors(gl: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    mask = scenes.sphere(SIZE).mask
    on = np.abs(gl.astype(np.int16) - ref.astype(np.int16)).max(axis=2)[mask]
    return {
        "mean": round(float(on.mean()), 3),
        "p99": float(np.percentile(on, 99)),
        "max": float(on.max()),
    }


def _save(name: str, gl: np.ndarray, ref: np.ndarray) -> None:
    import cv2

    OUT.mkdir(exist_ok=True)
    diff = np.clip(np.abs(gl.astype(np.int16) - ref.astype(np.int16)) * 8, 0, 255)
    cv2.imwrite(str(OUT / name), np.concatenate([gl, ref, diff.astype(np.uint8)], 1)[..., ::-1])


def _passes(errors: dict[str, float]) -> bool:
    return errors["mean"] <= MEAN_TOLERANCE and errors["p99"] <= P99_TOLERANCE


def _swap_axes(material: Material) -> Material:
    maps = dict(material.maps)
    maps["anisotropic_exponents"] = maps["anisotropic_exponents"][..., ::-1].copy()
    return Material(material.name, material.schema, maps, material.sources)


@pytest.mark.parametrize(
    ("family", "wrong"),
    [("beckmann", "ggx"), ("phong", "ggx"), ("ashikhmin_shirley", "phong")],
)
def test_each_analytic_lobe_matches_the_reference_and_a_wrong_one_does_not(
    viewport, base, family, wrong
):
    material = with_lobe(base, family)
    ref = _reference(material)
    gl = _gl(viewport, material)
    _save(f"viewport_gl_{family}_vs_reference.png", gl, ref)
    right = _errors(gl, ref)
    bad = _errors(_gl(viewport, material, lobe=wrong), ref)
    print(f"{family}: GL vs reference {right}; shown as {wrong}: {bad}")
    assert _passes(right)
    assert not _passes(bad)


def test_anisotropic_axes_follow_the_tangent_frame(viewport, base):
    material = with_lobe(base, "ashikhmin_shirley")
    ref = _reference(material)
    swapped = _errors(_gl(viewport, _swap_axes(material)), ref)
    print(f"ashikhmin_shirley with nu and nv swapped: {swapped}")
    assert not _passes(swapped)


@pytest.fixture(scope="module")
def small(base):
    # 256^2: the reference reads it at level 0 for this view, so both renderers
    # read the same quantiles (mips of quantiles and of tables differ)
    return resized(base, 256)


@pytest.mark.parametrize("family", ["sampled", "sampled_two_lobe"])
def test_sampled_lobes_from_their_inverse_cdf(viewport, small, family, request):
    if "sample-" in request.node.name:
        # Found when this test first ran on a second set (before, only on the
        # chessboard, whose limits these are): on the bundled sample's low
        # roughness the GPU's 16-node inverse-CDF lookup measures mean 1.02 / p99 6
        # (GGX table) and 0.83 / 5 (two-lobe), worse than the median-matched GGX
        # (0.32 / 3). With the samples' pdf from the nodes' central slope and a
        # mass-exact power-law tail: 0.87 / 6 and 0.78 / 5 (median GGX 0.29 / 3).
        # What is left is the table, not the lookup: the metal's alpha ~ 0.02 lobe
        # lies inside two of the 128 bins (0.7 deg), so the space's quantiles
        # there (PCHIP across bin edges) and the reference's bins read the same
        # under-resolved lobe differently: D(0) 1368 (GPU) vs 578 (reference) vs
        # 796 (closed form). Strict: it fails loudly once they agree.
        request.applymarker(
            pytest.mark.xfail(strict=True, reason="16-node GPU lookup too coarse at low roughness")
        )
    material = with_lobe(small, family)
    ref = _reference(material)
    gl = _gl(viewport, material)
    _save(f"viewport_gl_{family}_vs_reference.png", gl, ref)
    lookup = _errors(gl, ref)
    median = _errors(_gl(viewport, material, lobe="ggx"), ref)
    print(f"{family}: 16-level inverse-CDF lookup {lookup}; median-matched GGX {median}")
    assert lookup["mean"] <= SAMPLED_MEAN_TOLERANCE
    assert lookup["p99"] <= SAMPLED_P99_TOLERANCE
    if family == "sampled_two_lobe":
        # a shape no analytic lobe has: its median-matched GGX is the wrong lobe
        assert median["mean"] > SAMPLED_MEAN_TOLERANCE or median["p99"] > SAMPLED_P99_TOLERANCE


_PROBE = """
uniform float u_nodes[16];
uniform float u_power;
uniform vec2 u_size;
out vec4 frag_color;
void main() {
    g_x[0] = 0.0;
    for (int k = 0; k < 16; ++k) g_x[k + 1] = clamp(max(u_nodes[k], g_x[k]), 0.0, 1.0);
    g_x[17] = 1.0;
    vec2 p = floor(gl_FragCoord.xy);
    float t = (p.y * u_size.x + p.x + 0.5) / (u_size.x * u_size.y);
    float x = pow(t, u_power);
    frag_color = vec4(sampled_d(x), x, 0.0, 1.0);
}
"""


@pytest.mark.parametrize("alpha", [0.01, 0.05])
def test_shader_sampled_d_integrates_to_one(gl_context, alpha):
    """The shader's own ``sampled_d`` (compiled alone in a probe) over x = sin^2 theta:
    ``integral D (h.n) dw = pi integral_0^1 D dx`` by brute force on 2^20 points
    (``x = t^6``, dense where narrow lobes live). The lookup is the real path: the
    space's edit value -> ``shading_maps.quantile_table`` -> half floats (RGBA16F)."""
    from OpenGL import GL

    from matshop.spaces import get_space
    from matshop.viewport.gl import shaders
    from matshop.viewport.gl.fbo import Framebuffer
    from matshop.viewport.gl.shading_maps import quantile_table

    space = get_space("sampled")
    edges = space.edges
    tan2 = np.tan(np.minimum(edges, np.pi / 2 - 1e-12)) ** 2
    table = np.diff(tan2 / (alpha**2 + tan2)) / space.measure
    nodes = quantile_table(space.to_edit(table.astype(np.float32))[None, None], space.y)[0, 0]
    nodes = nodes.astype(np.float16).astype(np.float32)
    size, power = 1024, 6.0
    program = shaders.Program(
        shaders.BACKGROUND_VERTEX,
        shaders.VERSION + shaders._COMMON + shaders.SAMPLED_LOBE + _PROBE,
    )
    fbo = Framebuffer(size, size, (GL.GL_RGBA32F,))
    vao = GL.glGenVertexArrays(1)
    try:
        fbo.bind()
        program.use()
        GL.glUniform1fv(program.location("u_nodes"), 16, nodes)
        program.set("u_power", power)
        program.set("u_size", np.array([size, size], np.float32))
        GL.glDisable(GL.GL_DEPTH_TEST)
        GL.glBindVertexArray(vao)
        GL.glDrawArrays(GL.GL_TRIANGLES, 0, 3)
        out = fbo.read(flip=False).reshape(-1, 4)
    finally:
        GL.glDeleteVertexArrays(1, [vao])
        fbo.delete()
        program.delete()
    t = (np.arange(size * size) + 0.5) / (size * size)
    np.testing.assert_allclose(out[:, 1], t**power, rtol=1e-4, atol=1e-30)
    dx_dt = power * t ** (power - 1)
    integral = np.pi * np.sum(out[:, 0].astype(np.float64) * dx_dt) / t.size
    print(f"shader sampled D, GGX alpha {alpha}: integral D (h.n) dw = {integral:.5f}")
    assert integral == pytest.approx(1.0, abs=0.005)
