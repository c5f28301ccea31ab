"""The lighting choice (environment, turn, exposure) through ``matshop render``, against
closed forms written in ``tests/lighting_truth.py`` (not matshop's code):

- a white Lambertian in a uniform environment of radiance L reflects L;
- +1 stop doubles the linear radiance handed to the tone map (the .exr holds it; the
  .png is ACES + sRGB of it);
- a turn of 90 degrees carries a one-spot HDR (written here with OpenImageIO) 90 degrees
  round, and the lit sphere is the spot's cosine lobe about the turned direction;
- a bad environment is one line and exit 2, and nothing is written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from lighting_truth import Spot, display_code, white_lambertian_set, write_image
from oracle import file_codes

from matshop.cli import main
from matshop.errors import MatshopError
from matshop.render import scenes
from matshop.render.environment_choice import EnvironmentChoice

SIZE = 64


def sphere_interior(keep: float) -> np.ndarray:
    """Pixels of the reference sphere within ``keep`` of its projected radius (no silhouette,
    where Schlick's Fresnel grows even for a black specular)."""
    mask = scenes.sphere(SIZE).mask
    rows, cols = np.nonzero(mask)
    cy, cx = rows.mean(), cols.mean()
    radius = np.sqrt(mask.sum() / np.pi)
    yy, xx = np.mgrid[:SIZE, :SIZE]
    return mask & ((yy - cy) ** 2 + (xx - cx) ** 2 <= (keep * radius) ** 2)


def render_cli(tmp_path: Path, name: str, *options: str) -> Path:
    out = tmp_path / name
    white = white_lambertian_set(tmp_path / "white")
    argv = ["render", str(white), str(out), "--size", str(SIZE), "--samples", "4", *options]
    assert main(argv) == 0
    return out


def test_a_white_lambertian_in_a_uniform_environment_reflects_its_radiance(tmp_path) -> None:
    inside = sphere_interior(0.5)
    for radiance in (0.5, 2.0):
        exr = render_cli(tmp_path, f"u{radiance}.exr", f"--env=uniform:{radiance}")
        image = file_codes(exr)[..., :3]
        np.testing.assert_allclose(image[inside], radiance, rtol=2e-3)


def test_one_stop_doubles_the_radiance_before_the_tone_map(tmp_path) -> None:
    inside = sphere_interior(0.5)
    plain = file_codes(render_cli(tmp_path, "e0.exr", "--env=uniform:0.3"))[..., :3]
    brighter = file_codes(render_cli(tmp_path, "e1.exr", "--env=uniform:0.3", "--exposure", "1"))
    np.testing.assert_allclose(brighter[..., :3][inside], 2.0 * plain[inside], rtol=1e-5)
    np.testing.assert_allclose(brighter[..., :3][inside], 0.6, rtol=2e-3)
    # the picture: ACES then sRGB of 0.3 * 2^stops
    for stops in (1.0, -1.5):
        png = render_cli(tmp_path, f"e{stops}.png", "--env=uniform:0.3", f"--exposure={stops}")
        codes = file_codes(png)[..., :3][inside]
        assert np.abs(codes - display_code(0.3, stops)).max() <= 1, np.unique(codes)


def test_a_turn_of_90_degrees_moves_the_highlight_where_the_closed_form_says(tmp_path) -> None:
    # a 2x2 texel spot 10 degrees above the horizon at azimuth 135 (right, in front)
    spot = Spot(rows=64, row=28, col=112, size=2, radiance=300.0)
    hdr = spot.write(tmp_path / "spot.exr")
    gbuf = scenes.sphere(SIZE)
    inside = sphere_interior(0.85)
    normals = np.zeros((SIZE, SIZE, 3))
    normals[gbuf.mask] = gbuf.normal
    for turn in (0.0, 90.0):
        exr = render_cli(tmp_path, f"t{turn}.exr", f"--env={hdr}", f"--env-rotation={turn}")
        image = file_codes(exr)[..., 0]
        truth = spot.lambertian(normals[inside], turn)
        error = np.abs(image[inside] - truth).max() / truth.max()
        print(f"turn {turn}: worst error {error:.4f} of the peak {truth.max():.3f}")
        assert error < 0.02
        # the brightest pixel's normal points at the turned spot
        brightest = np.unravel_index(np.argmax(np.where(inside, image, -1.0)), image.shape)
        angle = np.degrees(np.arccos(normals[brightest] @ spot.centre(turn)))
        assert angle < 6.0, (turn, angle)
    # the turn moved it from the right half of the sphere to the left
    assert spot.centre(0.0)[0] > 0.5 and spot.centre(90.0)[0] < -0.5


@pytest.mark.parametrize(
    ("make", "says"),
    [
        (lambda d: d / "missing.hdr", "no such environment file"),
        (lambda d: write_image(d / "square.exr", np.ones((8, 8, 3), np.float32)), "2:1"),
        (lambda d: (d / "junk.hdr").write_bytes(b"not an image") and d / "junk.hdr", "junk.hdr"),
        (lambda d: d / "notes.txt", "equirectangular .hdr/.exr"),
    ],
)
def test_a_bad_environment_is_one_line_and_exit_2(tmp_path, capsys, make, says) -> None:
    env = make(tmp_path)
    out = tmp_path / "out" / "ball.png"
    white = white_lambertian_set(tmp_path / "white")
    assert main(["render", str(white), str(out), "--size", "8", f"--env={env}"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and says in err and "Traceback" not in err, err
    assert not out.exists() and not out.parent.exists()


def test_bad_turns_and_exposures_are_refused_in_one_line(tmp_path, capsys) -> None:
    white = white_lambertian_set(tmp_path / "white")
    for option in ("--env-rotation=nan", "--exposure=40"):
        assert main(["render", str(white), str(tmp_path / "x.png"), option]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and option.split("=")[0] in err, err


def test_a_choice_is_saved_and_read_back_as_the_same_choice(tmp_path) -> None:
    hdr = Spot(rows=8, row=2, col=3).write(tmp_path / "s.hdr")
    choice = EnvironmentChoice.parse(hdr, -90, 1.5)
    assert choice.rotation_deg == 270.0  # kept in [0, 360)
    assert EnvironmentChoice.from_json(choice.to_json()) == choice
    assert choice.label == "s.hdr" and EnvironmentChoice.parse("uniform:0.5").label == "Uniform 0.5"
    for bad in (
        {"environment": "moon"},
        {"rotation_deg": 3},
        "studio",
        {"environment": "sky", "exposure_stops": "x"},
    ):
        with pytest.raises(MatshopError):
            EnvironmentChoice.from_json(bad)
