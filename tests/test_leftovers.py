"""kill -9 at the worst moments: the next run that writes into the same folder removes the
dead process's temp and staging files and rolls a half-renamed file set back, whole;
a live writer's files are never touched; a full disk leaves everything as it was."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from matshop.cli import main
from matshop.errors import MatshopError
from matshop.io.leftovers import clean_leftovers
from matshop.io.project import load_project, save_project
from matshop.layers import Document
from matshop.material import Schema

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "sample"

# A child that stops (and waits to be killed) at a chosen point of a write.
_CHILD = textwrap.dedent(
    """
    import os, sys, time
    from pathlib import Path
    sys.path.insert(0, sys.argv[1])
    mode, target = sys.argv[2], Path(sys.argv[3])

    def stop(label):
        print(label, flush=True)
        time.sleep(600)

    if mode == "project":
        from matshop.io import project_store
        from matshop.io.project import load_project, save_project
        doc = load_project(target).document
        project_store._write_payload = lambda archive, payload: stop("writing")
        save_project(doc, target)
    else:  # a file set killed after its first rename
        from matshop.io import fileset
        from matshop.io.material_io import load_material, save_material
        material, _ = load_material(sys.argv[4])
        real, moved = os.replace, []
        def replace(src, dst):
            into_place = Path(dst).parent == target  # not a temp file inside staging
            if into_place and moved:
                stop("renaming")
            real(src, dst)
            if into_place:
                moved.append(dst)
        fileset.os.replace = replace
        save_material(material, target, overwrite=True)
    """
)


def _child(tmp_path: Path, *argv: object) -> subprocess.Popen:
    script = tmp_path / "child.py"
    script.write_text(_CHILD)
    return subprocess.Popen(
        [sys.executable, str(script), str(ROOT), *map(str, argv)],
        stdout=subprocess.PIPE,
        text=True,
    )


def _kill_when(child: subprocess.Popen, label: str) -> None:
    try:
        assert child.stdout is not None and child.stdout.readline().strip() == label
    finally:
        os.kill(child.pid, signal.SIGKILL)
        child.wait(timeout=30)


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture
def project(tmp_path: Path) -> Path:
    path = tmp_path / "work" / "p.matshop"
    path.parent.mkdir()
    doc = Document(Schema.from_names(["roughness"]), 16, 16, name="p")
    doc.insert_layer(doc.new_paint_layer("Paint"))
    save_project(doc, path)
    return path


def test_a_killed_project_save_leaves_a_temp_file_the_next_save_removes(
    project: Path, tmp_path: Path
) -> None:
    before = project.read_bytes()
    _kill_when(_child(tmp_path, "project", project), "writing")
    temps = list(project.parent.glob(".p.tmp-*.matshop"))
    assert len(temps) == 1 and project.read_bytes() == before
    # a live writer's temp file beside it (this process: it is running) stays
    live = project.parent / f".p.tmp-{os.getpid()}-0123abcd.matshop"
    live.write_bytes(b"in progress")
    assert main(["layer", "add", str(project), "paint", "--name", "after"]) == 0
    assert sorted(p.name for p in project.parent.iterdir()) == [live.name, "p.matshop"]
    assert load_project(project).document.layers[-1].name == "after"


def test_a_file_set_killed_mid_rename_is_rolled_back_whole(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["convert", str(SAMPLE), str(out)]) == 0
    old = _files(out)
    # a different set to write over it: the sample at half its values
    changed = tmp_path / "changed"
    assert main(["apply", str(SAMPLE), str(changed), "--op", "scale", "factor=0.5"]) == 0
    new = _files(changed)
    assert set(new) == set(old) and all(new[n] != old[n] for n in new)

    _kill_when(_child(tmp_path, "set", out, changed), "renaming")
    visible = _files(out)
    mixed = {n for n in old if visible[n] == new[n]}
    assert len(mixed) == 1  # killed after one rename: a mixed set on disk
    assert [p.name for p in out.iterdir() if p.name.startswith(".matshop-staging-")]

    # the next run into the folder (even one that then refuses) restores the old set
    assert main(["convert", str(SAMPLE), str(out)]) == 2
    assert _files(out) == old
    assert sorted(p.name for p in out.iterdir()) == sorted(old)


def test_only_dead_writers_leftovers_go(tmp_path: Path) -> None:
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    try:
        names = {
            f".a.tmp-{dead.pid}-0123abcd.png": "dead temp",
            f".a.tmp-{sleeper.pid}-0123abcd.png": "live temp",
            f".matshop-staging-{dead.pid}-xyz": "dead staging",
            f".matshop-staging-{sleeper.pid}-xyz": "live staging",
            "a.tmp-1-0123abcd.png": "not hidden: a user's file",
            ".notes.tmp": "not ours",
        }
        for name, what in names.items():
            if "staging" in what:
                (tmp_path / name).mkdir()
                (tmp_path / name / "x.png").write_bytes(b"x")
            else:
                (tmp_path / name).write_text(what)
        removed = clean_leftovers(tmp_path)
        assert sorted(p.name for p in removed) == sorted(n for n, w in names.items() if "dead" in w)
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
            n for n, w in names.items() if "dead" not in w
        )
    finally:
        sleeper.kill()
        sleeper.wait()


def test_a_full_disk_during_a_project_save_keeps_the_previous_file(
    project: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from matshop.io import project_store

    before = project.read_bytes()
    doc = load_project(project).document
    doc.insert_layer(doc.new_paint_layer("more"))

    def full(archive, payload) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(project_store, "_write_payload", full)
    with pytest.raises(MatshopError, match="No space left on device") as caught:
        save_project(doc, project)
    assert caught.value.path == str(project)
    assert project.read_bytes() == before
    assert sorted(p.name for p in project.parent.iterdir()) == ["p.matshop"]


def test_staging_folders_carry_their_owner(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from matshop.io import fileset

    seen: list[str] = []

    def spy(pending, path: Path) -> None:
        seen.append(path.parent.name)
        pending.write(path)

    monkeypatch.setattr(fileset, "write_one", spy)
    fileset.write_all(
        tmp_path / "o", [fileset.PendingFile("a.txt", lambda p: p.write_text("a"))], force=False
    )
    assert seen and seen[0].startswith(f".matshop-staging-{os.getpid()}-")
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["a.txt"]
    shutil.rmtree(tmp_path / "o")
