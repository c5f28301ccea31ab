"""Group membership: one pass over the stack against the per-group search it replaced.

    python benchmarks/groups.py [--groups 1000] [--depth 1]

A stack of ``--groups`` groups, each holding one fill layer nested ``--depth``
groups deep, on an 8x8 document (so flattening is all bookkeeping). Measured
in one run, best of 3:

- ``Document.group_starts()``: the lowest member of every group, one walk up
  each layer's (bounded) chain of groups;
- the same answer by the old rule, every group searching every layer below it
  (``Document.in_group`` per pair), as ``flatten_reference`` still does;
- a full flatten (all caches dropped), which calls ``group_starts`` per block.

Before this change a 1000-group flatten took 24 s (the old search ran per
group per block with an O(n) parent lookup); the ratio printed is old / new.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import best_time

from matshop.layers import Document
from matshop.layers.layer import GroupLayer
from matshop.material import Schema


def build(groups: int, depth: int) -> Document:
    doc = Document(Schema.from_names(["roughness"]), 8, 8, name="groups")
    for number in range(groups):
        parent = None
        chain = []
        for level in range(depth):
            group = doc.new_group_layer(f"g{number}.{level}", opacity=0.5)
            if parent is not None:
                group.put("parent", parent)
            chain.append(group)
            parent = group.id
        fill = doc.new_fill_layer(f"f{number}", value=np.array([1.0], np.float32))
        fill.put("parent", parent)
        for layer in [fill, *reversed(chain)]:
            doc.insert_layer(layer)
    return doc


def search_starts(doc: Document) -> dict[int, int]:
    """The old rule: each group scans every layer below it."""
    starts = {}
    for index, layer in enumerate(doc.layers):
        if isinstance(layer, GroupLayer):
            below = [b for b in range(index) if doc.in_group(doc.layers[b], layer.id)]
            starts[index] = min(below, default=index)
    return starts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--groups", type=int, default=1000)
    parser.add_argument("--depth", type=int, default=1)
    args = parser.parse_args()
    doc = build(args.groups, args.depth)
    assert doc.group_starts() == search_starts(doc)
    one_pass = best_time(doc.group_starts, 3)
    search = best_time(lambda: search_starts(doc), 3)

    def flatten() -> None:
        doc._compositor.invalidate_all()
        doc.flatten_edit()

    full = best_time(flatten, 3)
    print(f"{len(doc.layers)} layers, {args.groups} groups {args.depth} deep")
    print(f"group_starts one pass: {one_pass * 1e3:.1f} ms")
    print(f"per-group search:      {search * 1e3:.1f} ms  ({search / one_pass:.0f}x slower)")
    print(f"full flatten:          {full * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
