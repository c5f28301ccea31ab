"""matshop: a layer-based editor for spatially-varying materials.

Every material parameter is converted into an *editing space* in which plain,
linear image operations respect what the parameter means, and converted back
on export.
"""

import os as _os

__version__ = "0.1.0"

# numba's OpenMP workers otherwise spin after every parallel loop, taking
# cores from the next step (and from the UI thread) on a busy machine
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


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
