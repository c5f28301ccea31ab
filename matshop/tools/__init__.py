"""Interactive canvas tools (brush, eraser, clone stamp, eyedropper) and their panels.

:mod:`.base` and :mod:`.painting` hold the tools themselves and import no
widgets; :mod:`.settings`, :mod:`.widgets` and :mod:`.tool_panel` are Qt.
"""
