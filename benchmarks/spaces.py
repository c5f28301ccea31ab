"""Editing-space conversion speed, as ratios to a memory copy of the same bytes.

Absolute times drift on shared machines; the ratio to ``np.copyto`` measured
in the same run does not (much). Prints one line per case:

    python benchmarks/spaces.py [--repeat N]

Cases: the 2K PBR set (base color, normal, roughness, metallic; the shared
chessboard set when present, else synthetic maps of the same shape), each
space alone, and a 1K sampled-distribution texture (128 channels).
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import CHESSBOARD, best_time

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
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    material, what = pbr_material()
    print(f"PBR set: {what}; parameters {', '.join(material.schema.names)}")
    nbytes = sum(m.nbytes for m in material.maps.values())
    baseline = copy_time(nbytes, args.repeat)
    t_to = best_time(material.to_edit, args.repeat)
    edit = material.to_edit()
    t_from = best_time(edit.to_physical, args.repeat)
    report("2K PBR set: to_edit", t_to, baseline, nbytes)
    report("2K PBR set: from_edit", t_from, baseline, nbytes)
    report("2K PBR set: round trip (to_edit + from_edit)", t_to + t_from, baseline, nbytes)
    for param in material.schema.parameters:
        phys = material.maps[param.name]
        param_baseline = copy_time(phys.nbytes, args.repeat)
        space = param.space
        t = best_time(lambda s=space, p=phys: s.from_edit(s.to_edit(p)), args.repeat)
        report(f"  {param.name} ({param.space.name}) round trip", t, param_baseline, phys.nbytes)

    from matshop.spaces import get_space
    from matshop.spaces.sampled import d_from_ggx

    space = get_space("sampled")
    size = 1024
    rng = np.random.default_rng(1)
    alpha = rng.uniform(0.05, 1.0, size=(size, size))
    distribution = d_from_ggx(alpha, n=space.phys_channels)
    nbytes = distribution.nbytes
    baseline = copy_time(nbytes, args.repeat)
    t_to = best_time(lambda: space.to_edit(distribution), args.repeat)
    edit_d = space.to_edit(distribution)
    t_from = best_time(lambda: space.from_edit(edit_d), args.repeat)
    report("1K sampled distribution (128 ch): to_edit", t_to, baseline, nbytes)
    report("1K sampled distribution (128 ch): from_edit", t_from, baseline, nbytes)
    report("1K sampled distribution: round trip", t_to + t_from, baseline, nbytes)


if __name__ == "__main__":
    main()
