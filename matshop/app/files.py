"""Opening, saving, autosaving and closing documents.

A failed open or save shows the engine's one-line MatshopError in a message
box and leaves the current document exactly as it was (the new file is read
completely before anything is replaced). Autosave writes a recovery file on
a timer: beside the project (``io.recovery``), or for a texture set that was
never saved as a project, in the settings' recovery folder under a name
derived from the set's path, so opening the set again offers the restore.

Reading, writing and exporting run on a worker (:func:`.work.run_off_ui`):
the window keeps painting and shows a progress dialog while they last. The
worker reads a new file or a :meth:`Document.snapshot`, never the live document.
"""

from __future__ import annotations

import contextlib
import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, QTimer, Signal

from .. import buffers
from ..errors import MatshopError
from ..io.material_io import load_material
from ..io.normal_convention import convention_line
from ..io.project import discard_recovery, find_recovery, load_project, save_project, write_recovery
from ..io.textureset import SeveralMaterials, detect_texture_set
from ..layers import Document
from .prompts import Prompts
from .session import DocumentSession
from .settings import AppSettings
from .work import Cancelled, Work, run_off_ui

PROJECT_SUFFIX = ".matshop"


class _Declined(Exception):
    """The user cancelled opening after seeing the detected texture set."""


class FileController(QObject):
    """File actions of the main window."""

    #: a document was opened; carries the project's saved editor settings ({} for a set)
    opened = Signal(dict)
    message = Signal(str)
    recentChanged = Signal()

    def __init__(
        self,
        session: DocumentSession,
        prompts: Prompts,
        settings: AppSettings,
        editor_state: Callable[[], dict[str, Any]],
        busy: Callable[[], bool] = lambda: False,
    ) -> None:
        super().__init__()
        self.session = session
        #: a stroke is in progress (its tiles change in place: no snapshot now)
        self.busy = busy
        self.prompts = prompts
        self.settings = settings
        self.editor_state = editor_state
        self.autosave_timer = QTimer(self)
        self.autosave_timer.setInterval(settings.autosave_seconds() * 1000)
        self.autosave_timer.timeout.connect(self.autosave)
        self.autosave_timer.start()

    # -- opening -----------------------------------------------------------------

    def open_path(self, path: str | Path, *, review: bool = False) -> bool:
        """Open a texture set (folder or map) or a ``.matshop`` project; False if not opened.

        ``review``: show what was detected in a texture set first (the user may cancel);
        the open dialogs ask for it, scripts and tests open directly.
        """
        path = Path(path)
        try:
            doc, project_path, state, restored = self._load(path, review)
        except (_Declined, Cancelled):
            self.message.emit(f"Did not open {path.name}")
            return False
        except (MatshopError, OSError) as exc:
            self.prompts.error("Cannot open", _one_line(exc, path))
            return False
        if not self.close_document():
            return False
        self.session.set_document(
            doc, project_path=project_path, source_path=path, modified=restored
        )
        self.settings.add_recent(path)
        self.recentChanged.emit()
        self.opened.emit(state)
        what = "restored autosave of " if restored else ""
        normals = convention_line(doc.sources)
        self.message.emit(
            f"Opened {what}{path.name}: {doc.width}x{doc.height}, {', '.join(doc.schema.names)}"
            + (f" — {normals}" if normals else "")
        )
        return True

    def _load(self, path: Path, review: bool = False) -> tuple[Document, Path | None, dict, bool]:
        """(document, project path, editor settings, restored from autosave)."""
        if path.suffix.lower() == PROJECT_SUFFIX:
            key = path
            project_path: Path | None = path
        else:
            key = self.recovery_key(path)
            project_path = None
        recovery = find_recovery(key)
        if recovery is not None:
            if self.prompts.ask_restore(recovery):
                project = self._off_ui(f"Restoring {path.name}…", lambda _: load_project(recovery))
                return project.document, project_path, _editor(project.settings), True
            with contextlib.suppress(MatshopError):
                discard_recovery(key)
        if project_path is not None:
            project = self._off_ui(f"Opening {path.name}…", lambda _: load_project(path))
            return project.document, project_path, _editor(project.settings), False
        try:
            detected = detect_texture_set(path)
        except SeveralMaterials as several:
            chosen = self.prompts.choose_material(several.path or str(path), several.choices)
            if chosen is None:
                raise _Declined from None
            detected = detect_texture_set(path, material=chosen)
        if review:
            reviewed = self.prompts.review_texture_set(detected)
            if reviewed is None:
                raise _Declined
            detected = reviewed  # as the user corrected it

        def read(work: Work) -> Document:
            # per-file progress (and Cancel between files), then the conversion's own
            material, _report = load_material(detected, progress=work.progress)
            return Document.from_material(material.to_edit(progress=work.progress))

        return self._off_ui(f"Opening {path.name}…", read, cancellable=True), None, {}, False

    def _off_ui(self, label: str, fn: Callable[[Work], Any], cancellable: bool = False) -> Any:
        """``fn`` on a worker while the window stays live (see :mod:`.work`)."""
        return run_off_ui(self.prompts.parent, label, fn, cancellable=cancellable)

    def open_dialog(self) -> None:
        path = self.prompts.open_file(self._start_dir())
        if path is not None:
            self.open_path(path, review=True)

    def open_folder_dialog(self) -> None:
        path = self.prompts.open_folder(self._start_dir())
        if path is not None:
            self.open_path(path, review=True)

    def _start_dir(self) -> str:
        recent = self.settings.recent_files()
        return str(recent[0].parent) if recent else ""

    # -- saving ------------------------------------------------------------------

    def save(self) -> bool:
        if self.session.doc is None:
            return False
        if self.session.project_path is None:
            return self.save_as()
        return self.save_to(self.session.project_path)

    def save_as(self) -> bool:
        if self.session.doc is None:
            return False
        suggested = self.session.project_path or self._suggested_path()
        path = self.prompts.save_file(str(suggested))
        return False if path is None else self.save_to(path)

    def _suggested_path(self) -> Path:
        source = self.session.source_path
        folder = (
            source
            if source is not None and source.is_dir()
            else (source.parent if source is not None else Path.cwd())
        )
        name = self.session.doc.name if self.session.doc is not None else "untitled"
        return folder / f"{name}{PROJECT_SUFFIX}"

    def save_to(self, path: str | Path) -> bool:
        """Save the project to ``path`` (atomically); False after telling the user why not."""
        doc = self.session.doc
        if doc is None:
            return False
        path = Path(path)
        old_key = self.recovery_target()
        snapshot, settings = doc.snapshot(), {"editor": self.editor_state()}
        try:
            self._off_ui(
                f"Saving {path.name}…", lambda _: save_project(snapshot, path, settings=settings)
            )
        except MatshopError as exc:
            self.prompts.error("Cannot save", str(exc))
            return False
        self.session.mark_saved(path)
        if old_key is not None and old_key != path:
            with contextlib.suppress(MatshopError):  # the set's autosave is superseded
                discard_recovery(old_key)
        self.settings.add_recent(path)
        self.recentChanged.emit()
        self.message.emit(f"Saved {path.name}")
        return True

    # -- autosave and closing -------------------------------------------------------

    def recovery_key(self, source: Path) -> Path:
        """The stand-in project path whose recovery file holds a texture set's autosave."""
        digest = hashlib.sha1(str(source.resolve()).encode()).hexdigest()[:10]
        stem = source.stem if source.is_file() else source.name
        return self.settings.recovery_dir() / f"{stem}-{digest}{PROJECT_SUFFIX}"

    def recovery_target(self) -> Path | None:
        if self.session.doc is None:
            return None
        if self.session.project_path is not None:
            return self.session.project_path
        if self.session.source_path is None:
            return None
        return self.recovery_key(self.session.source_path)

    def autosave(self) -> Path | None:
        """Write the recovery file if there are changes it does not hold yet."""
        target = self.recovery_target()
        if target is None or not self.session.needs_autosave or self.busy():
            return None  # a stroke in progress: its tiles change; the next tick saves
        snapshot, settings = self.session.doc.snapshot(), {"editor": self.editor_state()}
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            written = self._off_ui(
                "Autosaving…", lambda _: write_recovery(snapshot, target, settings)
            )
        except (MatshopError, OSError) as exc:
            self.message.emit(f"Autosave failed: {_one_line(exc, target)}")
            return None
        self.session.mark_autosaved()
        self.message.emit(f"Autosaved to {written.name}")
        return written

    def close_document(self) -> bool:
        """Ask about unsaved changes; True when the document may go (then it is gone)."""
        if self.session.doc is None:
            return True
        if self.session.modified:
            answer = self.prompts.ask_save_changes(self.session.title)
            if answer == "cancel" or (answer == "save" and not self.save()):
                return False
        target = self.recovery_target()
        if target is not None:
            with contextlib.suppress(MatshopError):  # closed on purpose: nothing to restore
                discard_recovery(target)
        self.session.set_document(None)
        # the memory its results kept for reuse goes too (up to buffers.IDLE_LIMIT)
        buffers.release()
        return True

    # -- export --------------------------------------------------------------------

    def export(self) -> None:
        """Flatten and export with a preset of :mod:`matshop.export`; errors go to a message box.

        Before writing, the files the preset will write are listed (those that
        exist marked); existing files are replaced only when the user confirmed.
        """
        from ..export import builtin_preset_names, export_material, load_preset
        from .export_dialog import export_name, plan_export, plan_usd

        if self.session.doc is None:
            return
        preset = self.prompts.choose_preset(list(builtin_preset_names()))
        folder = None if preset is None else self.prompts.export_folder(self._start_dir())
        if preset is None or folder is None:
            return
        snapshot = self.session.doc.snapshot()
        try:
            material = self._off_ui(
                "Flattening the layers for export…",
                lambda _: snapshot.flatten_physical(),
                cancellable=True,
            )
            chosen = load_preset(preset)
            plan = plan_export(material, chosen, folder)
        except Cancelled:
            self.message.emit("Export cancelled")
            return
        except MatshopError as exc:
            self.prompts.error("Cannot export", str(exc))
            return
        usd_plan = plan_usd(material, folder)
        usd_label = "Also write USD (.usda, .usdz): the sphere with UsdPreviewSurface and MaterialX"
        extras = {"usd": (usd_label, [planned.line() for planned in usd_plan])}
        choices = self.prompts.confirm_export(
            [planned.line() for planned in plan],
            extras,
            size_hw=material.size,
            keep_variance=chosen.keep_variance,
        )
        if choices is None:
            self.message.emit("Export cancelled")
            return
        usd = choices.extras.get("usd", False)
        if usd:
            plan = plan + usd_plan
        finished = []

        def write(work: Work):
            summary = export_material(
                material,
                chosen,
                folder,
                name=export_name(material),
                size=choices.size,
                keep_variance=choices.keep_variance,
                force=any(planned.exists for planned in plan),  # the user saw them listed
                usdz=usd,
                progress=work.progress,  # Cancel between files: all-or-nothing
            )
            finished.append(summary)  # in place: a Cancel pressed from here on came too late
            return summary

        try:
            summary = self._off_ui(f"Exporting {preset} to {folder}…", write, cancellable=True)
        except Cancelled:
            if not finished:
                self.message.emit(f"Export cancelled: nothing written to {folder}")
                return
            summary = finished[0]
        except MatshopError as exc:
            self.prompts.error("Cannot export", str(exc))
            return
        self.message.emit(f"Exported {preset} to {folder} ({len(summary.files)} files)")


def _editor(settings: dict) -> dict:
    state = settings.get("editor", {}) if isinstance(settings, dict) else {}
    return state if isinstance(state, dict) else {}


def _one_line(exc: Exception, path: Path) -> str:
    if isinstance(exc, MatshopError):
        return str(exc)
    return str(MatshopError(getattr(exc, "strerror", None) or str(exc), path))
