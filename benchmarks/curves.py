"""Curves and levels as ratios to a memory copy of the same bytes, in one run.

    python benchmarks/curves.py [--repeat N] [--size 2048]

Data: the real 10-channel set of ``_common.real_set`` (the chessboard's maps
plus anisotropic exponents derived from them) in edit space, with its schema,
so the normal frame goes through the curve as one vector (frames included),
and its base colour alone (3 channels). Default ``remap="data"``: each call
also reads the channels' robust range. Baseline: ``np.copyto`` of the same
bytes into an existing array (the bandwidth limit; the ops also allocate
their result), timed right before each call of the op. The four goals' pairs
are taken in rounds (``_common.interleaved_ratios``), so each goal's median
spans the whole run. Goal (issue 16): <= 3x.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import goal, interleaved_ratios, real_set

from matshop.material import Material, Schema
from matshop.ops.curves import curves, levels

POINTS = [(0.0, 0.0), (0.3, 0.5), (1.0, 1.0)]
#: levels as the goals run it (``pair_accounting.py`` times the same call)
LEVELS = {"in_black": 0.1, "in_white": 0.9, "gamma": 1.4}
LIMIT = 3.0


def cases(material: Material) -> list[tuple[str, np.ndarray, Schema]]:
    """The goals' data: the set in edit space with its schema (so the frame goes
    through as one vector), and its base colour alone; each with its label."""
    edit = material.to_edit().data
    base_colour = Schema(material.schema.parameters[:1])
    return [
        ("10 ch incl. a frame", edit, material.schema),
        ("3 ch base colour", np.ascontiguousarray(edit[..., :3]), base_colour),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15, help="rounds of every pair")
    parser.add_argument("--size", type=int, default=2048)
    args = parser.parse_args()
    material, what = real_set(args.size)
    print(f"data: {what}")
    names, pairs = [], []
    for what, data, schema in cases(material):
        dst = np.empty_like(data)

        def copy(d=data, o=dst) -> None:
            np.copyto(o, d)

        def run_curves(d=data, s=schema) -> None:
            curves(d, points=POINTS, schema=s)

        def run_levels(d=data, s=schema) -> None:
            levels(d, schema=s, **LEVELS)

        for label, fn in (("curves", run_curves), ("levels", run_levels)):
            names.append(f"{label}, {what} / copy")
            pairs.append((fn, copy))
    for name, ratios in zip(names, interleaved_ratios(pairs, args.repeat), strict=True):
        goal(name, ratios, LIMIT)


if __name__ == "__main__":
    main()
