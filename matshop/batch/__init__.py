"""Batch: one recipe over a whole material library, as one Dask task per texture set.

    import matshop.batch
    report = matshop.batch("look.toml", ["library/"], "out/", workers=4)
    report = matshop.batch.run_batch("look.toml", "library/", "out/",
                                     scheduler="tcp://10.0.0.5:8786")

The package itself is callable (``matshop.batch(...)`` is :func:`run_batch`):
``matshop.batch`` is both this package's name and the API verb, and a module
attribute of the parent package cannot be both a module and a function.
"""

from __future__ import annotations

import sys
import types
from typing import Any

from .library import SetJob, find_sets
from .recipe import ExportPlan, Recipe, load_recipe
from .runner import BatchReport, run_batch

__all__ = [
    "BatchReport",
    "ExportPlan",
    "Recipe",
    "SetJob",
    "find_sets",
    "load_recipe",
    "run_batch",
]


class _CallableModule(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> BatchReport:
        return run_batch(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
