"""``matshop render`` and ``matshop figures`` end to end (small sizes)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from matshop.cli import main
from matshop.figures import make_figures
from matshop.io.images import read_image

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def test_render_writes_a_lit_ball(tmp_path):
    out = tmp_path / "ball.png"
    assert main(["render", str(SAMPLE), str(out), "--size", "48", "--samples", "4"]) == 0
    pixels, _ = read_image(out)
    assert pixels.shape == (48, 48, 3)
    # refuses to overwrite without --force
    assert main(["render", str(SAMPLE), str(out), "--size", "8"]) == 2


def test_render_writes_the_brdf_of_the_file_codes(tmp_path):
    """``matshop render --scene swatch --no-env --light`` to EXR (linear radiance): each
    pixel is one texel of the bundled sample, equal to the BRDF written in the test
    (``oracle.lit_swatch``) on the PNG files' own codes, read with OpenImageIO."""
    from oracle import file_codes, lit_swatch

    codes = {
        t: file_codes(SAMPLE / f"tiles_{t}.png")
        for t in ("basecolor", "metallic", "roughness", "normal")
    }
    out = tmp_path / "swatch.exr"
    argv = ["render", SAMPLE, out, "--scene", "swatch", "--size", "512", "--no-env"]
    assert main([str(a) for a in argv] + ["--light=-0.3,0.5,1:2"]) == 0
    truth = lit_swatch(
        codes["basecolor"][..., :3],
        codes["metallic"][..., 0],
        codes["roughness"][..., 0],
        codes["normal"][..., :3],
        (-0.3, 0.5, 1.0),
        2.0,
    )
    written = file_codes(out)
    seen = np.isfinite(truth).all(axis=2)
    assert seen.mean() > 0.999
    # the EXR holds half or single floats: 1e-3 relative covers half
    np.testing.assert_allclose(written[seen], truth[seen], rtol=1e-3, atol=1e-4)


def test_render_rejects_bad_lights_and_scenes(tmp_path, capsys):
    out = str(tmp_path / "x.png")
    assert main(["render", str(SAMPLE), out, "--light", "0,0,0"]) == 2
    assert main(["render", str(SAMPLE), out, "--scene", str(tmp_path / "no.obj")]) == 2
    assert "no such mesh" in capsys.readouterr().err


def test_plot_figures_carry_their_measurements(tmp_path):
    results = {r.name: r for r in make_figures(tmp_path, only=["fig4", "fig6"])}
    assert all(r.path.is_file() for r in results.values())
    # scaling the inverse CDF by s scales the median lobe angle by s
    assert results["fig4"].values["ratio_s1.5"] == pytest.approx(1.5, rel=0.01)
    # scaling profile radii keeps the albedo
    assert results["fig6"].values["albedo_ratio_s1.5"] == pytest.approx(1.0, abs=1e-3)
    assert np.isfinite(list(results["fig6"].values.values())).all()
