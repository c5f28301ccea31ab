"""matshop: a layer-based editor for spatially-varying materials.

Every material parameter is converted into an *editing space* in which plain,
linear image operations respect what the parameter means, and converted back
on export.
"""

__version__ = "0.1.0"
