"""matshop: a layer-based editor for spatially-varying materials.

Every material parameter is converted into an *editing space* in which plain,
linear image operations respect what the parameter means, and converted back
on export.
"""

import os as _os

from .huge_pages import follow_recorded_choice as _follow_recorded_choice

__version__ = "0.1.0"

# what OpenMP saw if it started before this import
_STARTED_POLICY = _os.environ.get("OMP_WAIT_POLICY", "").upper()
# numba's OpenMP workers otherwise spin for a few ms after every parallel loop,
# taking cores from the next step (and from the UI thread) on a busy machine
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


def _workers_started() -> bool:
    """Whether numba's OpenMP workers started before us (a script ran a parallel numba
    function first), so that the wait policy above came too late for them."""
    import sys

    parallel = sys.modules.get("numba.np.ufunc.parallel")
    if parallel is None or not getattr(parallel, "_is_initialized", False):
        return False
    import numba

    return numba.threading_layer() == "omp"


if _workers_started() and _STARTED_POLICY != "PASSIVE":
    import warnings as _warnings

    if _STARTED_POLICY == "ACTIVE":
        # workers that spin forever between loops would take a core from every
        # other step; one thread never wakes them, so matshop's kernels run on
        # this (importing) thread alone
        import numba as _numba

        _numba.set_num_threads(1)
        _warnings.warn(
            "numba's OpenMP threads started before matshop was imported, with "
            "OMP_WAIT_POLICY=ACTIVE: matshop's kernels run on one thread in this thread. "
            "Import matshop first (or set OMP_WAIT_POLICY=PASSIVE) to use all cores.",
            RuntimeWarning,
            stacklevel=2,
        )
    else:
        # libgomp's default policy spins ~3 ms after each parallel loop, then sleeps
        # (tests/test_import_order.py checks it): a 2K set converts as fast as with
        # the passive policy, but many small loops (tiles) spend several times the CPU
        _warnings.warn(
            "numba's OpenMP threads started before matshop was imported, without "
            "OMP_WAIT_POLICY=PASSIVE: they spin for a few ms after each parallel loop, "
            "which costs CPU when loops are small. Import matshop first (or set "
            "OMP_WAIT_POLICY=PASSIVE) to avoid it.",
            RuntimeWarning,
            stacklevel=2,
        )


# the memory policy `matshop warm-up` measured on this machine (numpy's huge pages)
_follow_recorded_choice()


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
