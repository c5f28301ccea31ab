"""The README's Python examples run as written (on the bundled sample)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from matshop.io.images import write_image

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_the_readme_has_its_examples() -> None:
    assert len(python_blocks()) >= 2


@pytest.mark.parametrize("number", range(len(python_blocks())))
def test_readme_python_example_runs(number: int, tmp_path: Path, monkeypatch) -> None:
    # the examples' paths, made real: the sample set, a mask, an output folder
    (tmp_path / "textures").mkdir()
    (tmp_path / "textures" / "rock").symlink_to(SAMPLE, target_is_directory=True)
    (tmp_path / "masks").mkdir()
    left = np.zeros((512, 512, 1), np.float32)
    left[:, :256] = 1.0
    write_image(tmp_path / "masks" / "left.png", left)
    (tmp_path / "out").mkdir()
    monkeypatch.chdir(tmp_path)
    before = set(tmp_path.rglob("*"))
    exec(compile(python_blocks()[number], f"README.md python block {number + 1}", "exec"), {})
    written = {p for p in set(tmp_path.rglob("*")) - before if p.is_file()}
    # every example ends by saving something, and what it saves opens again: a project
    # whose size is the sample's, or a texture set whose untouched maps are the sample's
    projects = [p for p in written if p.suffix == ".matshop"]
    maps = [p for p in written if p.suffix in (".png", ".exr")]
    assert projects or maps, written
    from matshop.io.material_io import load_material
    from matshop.io.project import load_project

    for project in projects:
        assert load_project(project).document.size == (512, 512)
    if maps:
        saved, _ = load_material(maps[0].parent)
        source, _ = load_material(SAMPLE)
        assert saved.size == source.size
        assert np.abs(saved.maps["metallic"] - source.maps["metallic"]).max() <= 0.5 / 255


def _headless_recipe() -> tuple[list[str], str]:
    """The README's "Layered projects, headless" commands and its stroke file, as written."""
    text = (ROOT / "README.md").read_text()
    section = text[text.index("### Layered projects, headless") :]
    commands = re.search(r"```sh\n(.*?)```", section, re.S).group(1)
    strokes = re.search(r"```json\n(.*?)```", section, re.S).group(1)
    lines = [line.split("  #")[0].strip() for line in commands.splitlines() if line.strip()]
    return lines, strokes


def _codes(path: Path) -> np.ndarray:
    import OpenImageIO as oiio

    buf = oiio.ImageBuf(str(path))
    spec = buf.spec()
    return np.asarray(buf.get_pixels(oiio.UINT8)).reshape(spec.height, spec.width, -1)


def test_readme_headless_recipe_runs_as_written(tmp_path: Path) -> None:
    """Every command of the recipe exits 0; the stroke paints what its swatch sets, AO stays."""
    import os
    import shlex
    import shutil
    import subprocess
    import sys

    lines, strokes = _headless_recipe()
    assert lines[0].startswith("matshop new") and any("matshop paint" in x for x in lines)
    (tmp_path / "steel").symlink_to(SAMPLE, target_is_directory=True)
    (tmp_path / "rust").symlink_to(SAMPLE, target_is_directory=True)
    ramp = np.repeat(np.linspace(0, 1, 512, dtype=np.float32)[None, :, None], 512, axis=0)
    write_image(tmp_path / "gradient.png", ramp)
    (tmp_path / "strokes.json").write_text(strokes)

    def matshop(line: str) -> None:
        argv = shlex.split(line)
        assert argv[0] == "matshop"
        run = subprocess.run(
            [sys.executable, "-m", "matshop", *argv[1:]],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
        )
        assert run.returncode == 0, f"{line}\n{run.stdout}\n{run.stderr}"

    for line in lines:  # the recipe as written
        matshop(line)
    shutil.copy(tmp_path / "rusty.matshop", tmp_path / "painted.matshop")
    # the same project without the painted layer
    matshop("matshop layer remove rusty.matshop Scratches")
    matshop("matshop flatten rusty.matshop bare/")
    painted, bare = tmp_path / "out", tmp_path / "bare"
    # the swatch sets no AO: the stroke left it exactly as the layers below make it
    ao = _codes(next(painted.glob("*_ao.png")))
    assert np.array_equal(ao, _codes(next(bare.glob("*_ao.png"))))
    base = _codes(next(painted.glob("*_basecolor.png")))
    assert not np.array_equal(base, _codes(next(bare.glob("*_basecolor.png"))))
    # the painted layer itself: on the stroke's centre line (hardness 0.7, full opacity) the
    # stroke file's bronze shows once the layers the recipe puts above it are hidden
    from matshop.io.project import load_project

    doc = load_project(tmp_path / "painted.matshop").document
    names = [layer.name for layer in doc.layers]
    for layer in doc.layers[names.index("Scratches") + 1 :]:
        doc.set_property(layer.id, "visible", False)
    shown = np.round(255 * doc.physical()["base_color"][125, 175])
    bronze = np.round(255 * np.array([0.45, 0.25, 0.08]))
    np.testing.assert_allclose(shown, bronze, atol=1)
