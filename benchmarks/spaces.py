"""Editing-space conversion speed, as ratios to a memory copy of the same bytes.

Absolute times drift on shared machines; the ratio to ``np.copyto`` measured
in the same run does not (much). Prints one line per case:

    python benchmarks/spaces.py [--repeat N]

Cases: the 2K PBR set (base color, normal, roughness, metallic; the shared
chessboard set when present, else synthetic maps of the same shape) and the
real 10-channel set of ``_common.real_set`` (that set plus anisotropic
exponents), each space alone, and a 1K sampled-distribution texture
(128 channels) made from the chessboard's roughness the way
``matshop.derive`` makes one. Goals (issue 16): round trip <= 8x, sampled
distributions <= 20x each way.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import CHESSBOARD, best_time, chessboard_material, goal, paired_ratios, real_set

from matshop.derive import MIN_ALPHA
from matshop.material import Material, Schema


def copy_time(nbytes: int, repeat: int) -> float:
    src = np.ones(nbytes // 4, dtype=np.float32)
    dst = np.empty_like(src)
    return best_time(lambda: np.copyto(dst, src), repeat)


def pbr_material() -> tuple[Material, str]:
    if CHESSBOARD.is_dir():
        from matshop.io.material_io import load_material

        material, _ = load_material(CHESSBOARD)
        return material, f"chessboard {material.size[1]}x{material.size[0]}"
    rng = np.random.default_rng(0)
    size = 2048
    normal = rng.normal(size=(size, size, 3)).astype(np.float32) * [0.2, 0.2, 1] + [0, 0, 1]
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    maps = {
        "base_color": rng.random((size, size, 3), dtype=np.float32),
        "metallic": rng.random((size, size, 1), dtype=np.float32),
        "roughness": rng.random((size, size, 1), dtype=np.float32),
        "normal": normal.astype(np.float32),
    }
    schema = Schema.from_names(["base_color", "metallic", "roughness", "normal"])
    return Material("synthetic", schema, maps), "synthetic 2048x2048 (chessboard absent)"


def report(label: str, seconds: float, baseline: float, nbytes: int) -> None:
    print(
        f"{label:44s} {seconds * 1e3:9.1f} ms   copy {baseline * 1e3:7.1f} ms"
        f"   ratio {seconds / baseline:6.2f}x   ({nbytes / 2**20:.0f} MiB)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    for material, what in (pbr_material(), real_set()):
        print(f"set: {what}; parameters {', '.join(material.schema.names)}")
        nbytes = sum(m.nbytes for m in material.maps.values())
        src = np.ones(nbytes // 4, dtype=np.float32)
        dst = np.empty_like(src)
        baseline = copy_time(nbytes, args.repeat)
        t_to = best_time(material.to_edit, args.repeat)
        edit = material.to_edit()
        t_from = best_time(edit.to_physical, args.repeat)
        report("  to_edit", t_to, baseline, nbytes)
        report("  from_edit", t_from, baseline, nbytes)
        for param in material.schema.parameters:
            phys = material.maps[param.name]
            param_baseline = copy_time(phys.nbytes, args.repeat)
            space = param.space
            t = best_time(lambda s=space, p=phys: s.from_edit(s.to_edit(p)), args.repeat)
            report(f"  {param.name} ({space.name}) round trip", t, param_baseline, phys.nbytes)
        ratios = paired_ratios(
            lambda m=material: m.to_edit().to_physical(),
            lambda d=dst, s=src: np.copyto(d, s),
            args.repeat,
        )
        channels = material.schema.edit_width
        goal(f"spaces round trip, 2K set of {channels} edit ch / copy", ratios, 8.0)

    from matshop.spaces import get_space
    from matshop.spaces.sampled import d_from_ggx

    space = get_space("sampled")
    roughness = (
        chessboard_material().maps["roughness"][:1024, :1024, 0]
        if CHESSBOARD.is_dir()
        else (np.random.default_rng(1).uniform(0.2, 1.0, size=(1024, 1024)))
    )
    # the engine's own derivation (matshop.derive): alpha = r^2, floored at MIN_ALPHA
    alpha = np.clip(roughness.astype(np.float64) ** 2, MIN_ALPHA, 1.0)
    distribution = d_from_ggx(alpha, n=space.phys_channels)
    src = np.ones(distribution.size, dtype=np.float32)
    dst = np.empty_like(src)
    edit_d = space.to_edit(distribution)
    print("1K sampled distribution (128 ch) from the chessboard's roughness (GGX, alpha = r^2)")
    for label, fn in (
        ("to_edit", lambda: space.to_edit(distribution)),
        ("from_edit", lambda: space.from_edit(edit_d)),
    ):
        ratios = paired_ratios(fn, lambda: np.copyto(dst, src), args.repeat)
        goal(f"sampled distribution 128 ch, {label} / copy", ratios, 20.0)


if __name__ == "__main__":
    main()
