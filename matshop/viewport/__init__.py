"""Views of the document: the 2D texture canvas (and, later, the 3D viewport).

:mod:`.display`, :mod:`.view` and :mod:`.display_cache` are Qt-free numpy;
:mod:`.canvas` is the QWidget.
"""
