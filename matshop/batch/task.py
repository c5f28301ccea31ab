"""One batch task: read one texture set, edit it, write it all-or-nothing. Runs in a worker.

Only the job (paths) and the recipe (op settings) travel to the worker; the
set is read and written there, on storage the workers share, so nothing
large crosses the scheduler. A set that fails is a report row with a
one-line reason, not an exception: Dask keeps its own retries for what only
a lost worker causes.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import resource
import sys
import time
from functools import partial
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from .library import SetJob
from .recipe import Recipe

#: hidden folder under OUT where tasks note their starts (a restarted task counts them)
ATTEMPTS_DIR = ".matshop-batch"


def run_set(job: SetJob, recipe: Recipe, out: str, *, force: bool = False) -> dict[str, Any]:
    """Edit the set ``job`` names as ``recipe`` says into ``out``; return its report row."""
    started = time.perf_counter()
    target = Path(out).joinpath(*job.out_parts)
    row: dict[str, Any] = {
        "input": str(job.source),
        "material": job.material,
        "output": str(target),
        "attempt": _count_attempt(Path(out), job),
        "worker": _worker_name(),
        "notes": [],
    }
    existed = target.exists()
    try:
        written, notes = _edit_and_write(job, recipe, target, force=force)
        row.update(status="ok", outputs=[str(p) for p in written], error=None, notes=notes)
    except MatshopError as exc:
        row.update(status="failed", outputs=[], error=str(exc))
    except Exception as exc:  # a bug or a library's exception: still one line, others go on
        text = " ".join(str(exc).split()) or "no message"
        row.update(status="failed", outputs=[], error=f"{type(exc).__name__}: {text}")
    if row["status"] == "failed" and not existed:
        _remove_empty(target, Path(out))
    row["seconds"] = round(time.perf_counter() - started, 3)
    row["peak_rss_mb"] = _peak_rss_mb()
    return row


def _edit_and_write(
    job: SetJob, recipe: Recipe, target: Path, *, force: bool
) -> tuple[list[Path], list[str]]:
    """The set's files written, and notes worth a line in the report."""
    from ..api import EditableMaterial, load_mask
    from ..opchain import run_steps

    if recipe.look is not None:
        from ..io.material_io import load_material
        from .look import apply_look

        material, _ = load_material(job.source, material=job.material)
        edited, notes = apply_look(recipe.look, material)
    else:
        m = EditableMaterial.from_path(job.source, material=job.material)
        run_steps(m, recipe.steps, mask_loader=partial(load_mask, resample=True))
        edited, notes = m.physical(), []
    if recipe.export is None:
        from ..io.material_io import save_material

        return save_material(edited, target, overwrite=force), notes
    from ..export.core import export_material

    plan = recipe.export
    summary = export_material(
        edited,
        plan.preset,
        target,
        size=plan.size,
        strict=plan.strict,
        glb=plan.glb,
        mtlx=plan.mtlx,
        force=force,
    )
    return [f.path for f in summary.files], notes + summary.warnings


def attempt_file(out: Path, job: SetJob) -> Path:
    digest = hashlib.sha1(repr((str(job.source), job.material)).encode()).hexdigest()[:16]
    return out / ATTEMPTS_DIR / f"{digest}.starts"


def _count_attempt(out: Path, job: SetJob) -> int:
    """This start's number for ``job`` (2 and more: a worker was lost while it ran)."""
    marker = attempt_file(out, job)
    try:
        marker.parent.mkdir(parents=True, exist_ok=True)
        with open(marker, "a", encoding="utf-8") as f:  # one line per start
            f.write(f"{os.getpid()}\n")
        return len(marker.read_text(encoding="utf-8").splitlines())
    except OSError:
        return 1


def _worker_name() -> str | None:
    with contextlib.suppress(ImportError, ValueError):
        from distributed import get_worker

        return get_worker().address
    return None


def _peak_rss_mb() -> float:
    """The worker process's peak resident memory so far (not this task's alone)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return round(peak / (1 << 20 if sys.platform == "darwin" else 1 << 10), 1)


def _remove_empty(target: Path, out: Path) -> None:
    """Take back the folders a failed set created (only empty ones, never past OUT)."""
    folder = target
    while folder != out and out in folder.parents:
        try:
            folder.rmdir()
        except OSError:
            return
        folder = folder.parent
