"""Running a recipe over many sets on Dask distributed: one task per set.

Without a scheduler address the tasks run on a :class:`distributed.LocalCluster`
of worker processes on 127.0.0.1; with one (``tcp://host:port``) they go to
that cluster's workers. Either way the same task function runs, each result is
one row appended to ``OUT/batch-report.jsonl`` as it arrives (a crashed run
keeps what finished; ``resume`` skips it), and a task whose worker died is
rescheduled by Dask itself (the scheduler's ``allowed-failures``); the row's
``attempt`` says when that happened.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import shutil
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import MatshopError
from .library import SetJob, find_sets
from .recipe import Recipe, load_recipe
from .task import ATTEMPTS_DIR, run_set

REPORT_NAME = "batch-report.jsonl"


@dataclass
class BatchReport:
    """The rows of one run (``status``: ok, failed or skipped) and where they were written."""

    path: Path
    rows: list[dict[str, Any]] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def failed(self) -> list[dict[str, Any]]:
        return [r for r in self.rows if r["status"] == "failed"]

    def count(self, status: str) -> int:
        return sum(r["status"] == status for r in self.rows)

    @property
    def exit_status(self) -> int:
        """0 when every set succeeded (or was done before), 1 when some failed."""
        return 1 if self.failed else 0

    def summary(self) -> str:
        return (
            f"{len(self.rows)} sets: {self.count('ok')} ok, {self.count('failed')} failed, "
            f"{self.count('skipped')} skipped in {self.seconds:.1f} s; report {self.path}"
        )


def run_batch(
    recipe: Recipe | str | os.PathLike[str],
    inputs: Sequence[str | os.PathLike[str]] | str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    pattern: str | None = None,
    resume: bool = False,
    force: bool = False,
    preset: str | None = None,
    size: int | None = None,
    echo: Callable[[str], None] | None = None,
    progress: bool = False,
) -> BatchReport:
    """Edit every texture set under ``inputs`` as ``recipe`` says, into ``out``.

    Parameters
    ----------
    recipe : a TOML recipe (path), or a loaded :class:`Recipe`.
    inputs : library folders (searched recursively) or single maps of sets.
    out : output folder; each set's result goes to its mirrored sub-folder.
    workers : processes of the local cluster (default: the machine's cores).
    scheduler : address of a running Dask scheduler (``tcp://host:port``) instead.
    pattern : glob over the sets' output folders relative to ``out`` (``ambientcg/*``).
    resume : skip sets the report in ``out`` lists as ok with all their files present.
    force : replace existing output files.
    preset, size : an export preset / longest side over the recipe's ``[export]``.
    echo : called with one line per finished set (None: quiet).
    progress : draw a progress bar (counts and ETA) on stderr.

    Raises
    ------
    MatshopError : a bad recipe, input or option, before any set is touched.
    """
    started = time.perf_counter()
    if workers is not None and scheduler is not None:
        raise MatshopError("give --workers or --scheduler, not both")
    if workers is not None and workers < 1:
        raise MatshopError(f"--workers must be at least 1, got {workers}")
    if not isinstance(recipe, Recipe):
        recipe = load_recipe(recipe)
    recipe = recipe.with_export(preset, size)
    if isinstance(inputs, str | os.PathLike):
        inputs = [inputs]
    out = Path(out).resolve()
    if out.exists() and not out.is_dir():
        raise MatshopError("output exists and is not a folder", out)
    jobs = find_sets(inputs, pattern, exclude=out)
    if not jobs:
        matching = f" matching {pattern!r}" if pattern else ""
        raise MatshopError(f"no texture sets found{matching}", ", ".join(map(str, inputs)))
    report = BatchReport(out / REPORT_NAME)
    done = _done_before(report.path) if resume else {}
    todo = [j for j in jobs if _key(j) not in done]
    report.rows += [dict(done[_key(j)], status="skipped") for j in jobs if _key(j) in done]
    out.mkdir(parents=True, exist_ok=True)
    with open(report.path, "a" if resume else "w", encoding="utf-8") as log:
        for row in _run(todo, recipe, out, force, workers, scheduler, progress, echo):
            log.write(json.dumps(row) + "\n")
            log.flush()
            report.rows.append(row)
    shutil.rmtree(out / ATTEMPTS_DIR, ignore_errors=True)
    report.seconds = time.perf_counter() - started
    return report


def _key(job_or_row: SetJob | dict[str, Any]) -> tuple[str, str | None]:
    if isinstance(job_or_row, SetJob):
        return str(job_or_row.source), job_or_row.material
    return job_or_row["input"], job_or_row["material"]


def _done_before(path: Path) -> dict[tuple[str, str | None], dict[str, Any]]:
    """Rows of an earlier report whose set succeeded and whose files are all still there."""
    done = {}
    if not path.is_file():
        return done
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            row = json.loads(line)
            if row["status"] == "ok" and all(Path(p).is_file() for p in row["outputs"]):
                done[_key(row)] = row
        except (ValueError, KeyError, TypeError):
            continue  # a line cut short by a crash: that set runs again
    return done


def _run(
    jobs: list[SetJob],
    recipe: Recipe,
    out: Path,
    force: bool,
    workers: int | None,
    scheduler: str | None,
    progress: bool,
    echo: Callable[[str], None] | None,
) -> Iterator[dict[str, Any]]:
    """Yield one report row per job as the cluster finishes them."""
    if not jobs:
        return
    from distributed import as_completed
    from tqdm import tqdm

    with _client(workers, scheduler) as client:
        futures = {
            client.submit(run_set, job, recipe, str(out), force=force, pure=False): job
            for job in jobs
        }
        bar = tqdm(total=len(jobs), unit="set", file=sys.stderr, disable=not progress)
        try:
            for future in as_completed(futures):
                job = futures[future]
                try:
                    row = future.result()
                except Exception as exc:  # KilledWorker: lost a worker too often
                    row = _lost(job, out, exc)
                bar.update()
                if echo is not None:
                    line = f"{row['status']:6s} {job.label} ({row.get('seconds', 0):.2f} s)"
                    if row["status"] != "ok":
                        line += f": {row['error']}"
                    elif row.get("attempt", 1) > 1:
                        line += f" on attempt {row['attempt']} (a worker was lost)"
                    echo(line)
                yield row
        finally:
            bar.close()


def _lost(job: SetJob, out: Path, exc: BaseException) -> dict[str, Any]:
    text = " ".join(str(exc).split())
    return {
        "input": str(job.source),
        "material": job.material,
        "output": str(out.joinpath(*job.out_parts)),
        "status": "failed",
        "outputs": [],
        "error": f"{type(exc).__name__}: {text}",
        "seconds": 0.0,
    }


@contextlib.contextmanager
def _client(workers: int | None, scheduler: str | None) -> Iterator[Any]:
    """A Dask client on a running scheduler, or on a fresh LocalCluster closed after."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")
        except OSError as exc:
            raise MatshopError(f"cannot reach the scheduler: {exc}", scheduler) from None
        with client:
            yield client
        return
    n = workers or os.cpu_count() or 1
    threads = max(1, (os.cpu_count() or 1) // n)
    with (
        LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            silence_logs=logging.ERROR,
            # each worker process gets its share of the cores for numba/OpenMP
            env={"NUMBA_NUM_THREADS": str(threads), "OMP_NUM_THREADS": str(threads)},
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client
