"""``matshop ops``: every operation with its parameters, units, defaults and ranges."""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = "List every operation with its parameters, units, defaults and ranges."
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ...ops import all_ops

    for spec in all_ops().values():
        kind = "linear" if spec.linear else "non-linear"
        print(f"{spec.name}: {spec.summary} ({kind})")
        for extra in spec.all_inputs:
            need = "required" if extra in spec.inputs else "optional"
            print(f"    {extra + '=PATH':<26s} another texture set ({need})")
        for param in spec.params:
            facts = []
            if param.unit:
                facts.append(param.unit)
            if param.hard_range and param.kind in ("float", "int"):
                facts.append(f"{param.hard_range[0]:g} to {param.hard_range[1]:g}")
            if param.choices:
                facts.append(" | ".join(param.choices))
            setting = f"{param.name}={param.format(param.default)}"
            print(f"    {setting:<26s} {param.doc}" + (f" ({'; '.join(facts)})" if facts else ""))
    return 0
