"""``matshop warm-up``: compile numba's kernels now, so first uses do not (:mod:`...warmup`)."""

from __future__ import annotations

import argparse
import time


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Compile matshop's numba kernels into numba's on-disk cache by running the engine "
        "once on small data, so the editor's first stroke, open or HDR does not compile "
        "them, and matshop's modules to Python bytecode, as a regular install does. It also "
        "measures whether numpy's huge pages make fresh memory slower on this machine (some "
        "virtual machines) and records the choice every matshop process follows; "
        "NUMPY_MADVISE_HUGEPAGE overrides it. Run "
        "once after installing or updating (the editor starts it by itself when the cache "
        "is cold). Honours NUMBA_CACHE_DIR."
    )
    parser.add_argument(
        "--if-cold",
        action="store_true",
        help="compile no kernel when a warm-up already ran on these sources, numba and CPU",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ... import warmup

    if args.if_cold and warmup.is_warm():
        warmup.compile_package()  # also after a source edit that touched no kernel module
        if warmup.huge_pages.recorded_choice() is None:  # a cache warmed before it was measured
            warmup.choose_huge_pages()
        print(f"kernels already compiled ({warmup.stamp_path().parent})")
        return 0
    print("compiling matshop's kernels ahead of first use (once after installing)")
    began = time.perf_counter()
    compiled, loaded = warmup.warm_up(lambda line: print(line, flush=True))
    print(
        f"done in {time.perf_counter() - began:.0f} s: {compiled} compiled, {loaded} already "
        f"in the cache ({warmup.stamp_path().parent})"
    )
    return 0
