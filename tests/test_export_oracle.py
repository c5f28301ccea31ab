"""Every engine preset's files, channel by channel, against the source files' own codes.

The layouts below are written by hand from the engines' documentation
(CONVENTIONS.md), not read from the preset files; both sides are read with
OpenImageIO directly (unassociated alpha), never through ``load_material``.
The source is the bundled sample: 8-bit codes, so a channel copied through
edit space and back must come out as the same code (one either way for the
dither of 8-bit outputs).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from oracle import file_codes as codes

from matshop.cli import main

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


def source(tag: str, channel: int = 0) -> np.ndarray:
    return codes(SAMPLE / f"tiles_{tag}.png")[..., channel]


def normal_gl(channel: int) -> np.ndarray:
    return source("normal", channel)


def normal_dx(channel: int) -> np.ndarray:
    return 255 - source("normal", 1) if channel == 1 else source("normal", channel)


def constant(value: int):
    return lambda: np.full(source("ao").shape, value)


BASE = [lambda c=c: source("basecolor", c) for c in range(3)]
GL = [lambda c=c: normal_gl(c) for c in range(3)]
DX = [lambda c=c: normal_dx(c) for c in range(3)]
AO, ROUGH, METAL = (
    (lambda: source("ao")),
    (lambda: source("roughness")),
    (lambda: source("metallic")),
)
SMOOTH = lambda: 255 - source("roughness")  # noqa: E731

#: preset -> file -> what each channel must hold
LAYOUTS = {
    "unreal": {
        "tiles_BaseColor.png": BASE,
        "tiles_Normal.png": DX,
        "tiles_ORM.png": [AO, ROUGH, METAL],
    },
    "gltf": {
        "tiles_baseColor.png": BASE,
        "tiles_normal.png": GL,
        "tiles_occlusionRoughnessMetallic.png": [AO, ROUGH, METAL],
    },
    "godot": {
        "tiles_albedo.png": BASE,
        "tiles_normal.png": GL,
        "tiles_orm.png": [AO, ROUGH, METAL],
    },
    "unity_urp": {
        "tiles_BaseMap.png": BASE,
        "tiles_Normal.png": GL,
        "tiles_MetallicSmoothness.png": [METAL, AO, None, SMOOTH],
        "tiles_Occlusion.png": [AO],
    },
    "unity_hdrp": {
        "tiles_BaseMap.png": BASE,
        "tiles_Normal.png": GL,
        "tiles_MaskMap.png": [METAL, AO, constant(255), SMOOTH],
    },
}


@pytest.mark.parametrize("preset", sorted(LAYOUTS))
def test_every_channel_holds_the_source_codes(preset: str, tmp_path: Path) -> None:
    out = tmp_path / preset
    assert main(["export", str(SAMPLE), str(out), "--preset", preset]) == 0
    layout = LAYOUTS[preset]
    assert sorted(p.name for p in out.iterdir()) == sorted(layout)
    for name, channels in layout.items():
        written = codes(out / name)
        assert written.shape[2] >= len(channels), (name, written.shape)
        for index, truth in enumerate(channels):
            if truth is None:
                continue  # a channel the engine ignores
            worst = np.abs(written[..., index] - truth()).max()
            assert worst <= 1, f"{name} channel {'RGBA'[index]}: {worst} codes off"
