"""matshop: a layer-based editor for spatially-varying materials.

Every material parameter is converted into an *editing space* in which plain,
linear image operations respect what the parameter means, and converted back
on export.
"""

import os as _os

__version__ = "0.1.0"

# what OpenMP saw if it started before this import
_STARTED_POLICY = _os.environ.get("OMP_WAIT_POLICY", "")
# numba's OpenMP workers otherwise spin after every parallel loop, taking
# cores from the next step (and from the UI thread) on a busy machine
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


def _spinning_workers_started() -> bool:
    """Whether numba's OpenMP workers started before us without a passive wait policy.

    OpenMP reads OMP_WAIT_POLICY once, when it starts; a script that ran a
    parallel numba function before importing matshop has workers that spin
    after every parallel loop (to_edit measured 6-10x slower under load).
    """
    import sys

    parallel = sys.modules.get("numba.np.ufunc.parallel")
    if parallel is None or not getattr(parallel, "_is_initialized", False):
        return False
    import numba

    return numba.threading_layer() == "omp" and _STARTED_POLICY.upper() != "PASSIVE"


if _spinning_workers_started():
    # the workers cannot be told to sleep any more; one thread never wakes them,
    # so this (importing) thread runs matshop's kernels alone instead
    import warnings as _warnings

    import numba as _numba

    _numba.set_num_threads(1)
    _warnings.warn(
        "numba's OpenMP threads started before matshop was imported, without "
        "OMP_WAIT_POLICY=PASSIVE: matshop's kernels run on one thread in this thread. "
        "Import matshop first (or set OMP_WAIT_POLICY=PASSIVE) to use all cores.",
        RuntimeWarning,
        stacklevel=2,
    )


def open(path, **load_options):  # noqa: A001 - matshop.open is the API's front door
    """Open a texture set for editing; see :func:`matshop.api.open`."""
    from .api import open as _open

    return _open(path, **load_options)


def __getattr__(name):
    # `matshop.batch(...)` after a plain `import matshop`: the batch package (which is
    # callable, see matshop/batch/__init__.py) loads Dask only when first used
    if name == "batch":
        import importlib

        return importlib.import_module(".batch", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
