"""How PNG files are written: zlib level and row filter, each chosen by measurement.

A module of its own with no imports, so that option parsers and preset
validation can name the defaults without loading OpenImageIO or numpy.
"""

#: zlib level of PNGs written (OpenImageIO's default is 6). Chosen by
#: benchmarks/png_level.py on the chessboard maps: level 2 writes in about a third
#: of level 6's time for files 10-25 % larger; level 1 is hardly faster.
PNG_LEVEL = 2
#: libpng's row filters (its ``PNG_FILTER_*`` bits, OpenImageIO's ``png:filter``):
#: ``adaptive`` tries all five on every row and keeps the best guess (libpng's default)
PNG_FILTERS = {"adaptive": 0xF8, "none": 0x08, "sub": 0x10, "up": 0x20, "avg": 0x40, "paeth": 0x80}
#: the row filter of PNGs written. Chosen by benchmarks/png_level.py on the
#: chessboard maps as read and blurred (8 files, level 2, CPU time against
#: cv2.imwrite's at the same level): adaptive 1.63x for files 1.00x cv2's size,
#: "up" 1.01x for 1.04x; sub, avg and none 1.07-1.10x for 1.2-1.5x, paeth 1.27x.
PNG_FILTER = "up"

__all__ = ["PNG_FILTER", "PNG_FILTERS", "PNG_LEVEL"]
