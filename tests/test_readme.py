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
    # every example ends by saving something: a texture set or a project
    assert any(p.suffix in (".png", ".exr", ".matshop") for p in written), written
