"""Finding the texture sets of a library: every material of every folder, recursively.

A library folder may hold one material per folder (Poly Haven, ambientCG,
Megascans downloads) or several in one folder (a MaterialX example, a
Substance export); :func:`~matshop.io.textureset.list_materials` names them
and each becomes one job. Outputs mirror the library's folders under OUT with
every part made a plain name (:func:`~matshop.io.safe_names.safe_stem`), so no
folder name in the library can send a write outside OUT.
"""

from __future__ import annotations

import fnmatch
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import MatshopError
from ..io.map_names import IMAGE_EXTENSIONS
from ..io.safe_names import safe_stem
from ..io.textureset import detect_texture_set, list_materials


@dataclass(frozen=True)
class SetJob:
    """One texture set to edit: where it is and where its result goes under OUT."""

    folder: Path
    #: which material of the folder (None: the folder's only one, or the one ``file`` names)
    material: str | None
    #: output folder relative to OUT, each part a plain name
    out_parts: tuple[str, ...]
    #: a map of the set, when the input named one file rather than a folder
    file: Path | None = None

    @property
    def label(self) -> str:
        """How reports and ``--pattern`` name the set: its output folder under OUT."""
        return "/".join(self.out_parts) or "."

    @property
    def source(self) -> Path:
        return self.file or self.folder


def find_sets(
    inputs: Sequence[str | os.PathLike[str]],
    pattern: str | None = None,
    *,
    exclude: Path | None = None,
) -> list[SetJob]:
    """Every texture set under ``inputs`` (folders searched recursively, or single maps).

    ``pattern`` keeps the sets whose :attr:`SetJob.label` matches the glob;
    ``exclude`` is a folder not searched (the batch's own output).
    Raises MatshopError for an input that does not exist.
    """
    jobs: list[SetJob] = []
    for raw in inputs:
        root = Path(raw).absolute()  # workers elsewhere do not share our cwd
        if not root.exists():
            raise MatshopError("not found", root)
        prefix = (safe_stem(root.resolve().name, "input"),) if len(inputs) > 1 else ()
        if root.is_file():
            ts = detect_texture_set(root)
            jobs.append(SetJob(root.parent, None, (*prefix, safe_stem(ts.name)), file=root))
            continue
        jobs.extend(_jobs_under(root, prefix, exclude))
    if pattern is not None:
        jobs = [j for j in jobs if fnmatch.fnmatch(j.label, pattern)]
    return _distinct_outputs(jobs)


def _jobs_under(root: Path, prefix: tuple[str, ...], exclude: Path | None) -> list[SetJob]:
    jobs = []
    for folder, dirs, files in os.walk(root):  # symlinked folders are not followed
        if exclude is not None and Path(folder).resolve() == exclude:
            dirs[:] = []
            continue
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        if not any(Path(f).suffix.lower() in IMAGE_EXTENSIONS for f in files):
            continue
        here = Path(folder)
        parts = (*prefix, *(safe_stem(p, "folder") for p in here.relative_to(root).parts))
        try:
            materials = list_materials(here)
        except MatshopError:  # unreadable folder: its job fails with the reason
            materials = [""]
        if len(materials) == 1:
            jobs.append(SetJob(here, None, parts))
        else:
            jobs.extend(SetJob(here, m, (*parts, safe_stem(m))) for m in materials)
    return jobs


def _distinct_outputs(jobs: list[SetJob]) -> list[SetJob]:
    """Two sets never share an output folder (``a/b`` beside material ``b`` of ``a``)."""
    seen: set[tuple[str, ...]] = set()
    result = []
    for job in jobs:
        parts, n = job.out_parts, 1
        while parts in seen:
            n += 1
            parts = (*job.out_parts[:-1], f"{job.out_parts[-1] if job.out_parts else 'set'}-{n}")
        seen.add(parts)
        result.append(SetJob(job.folder, job.material, parts, job.file))
    return result
