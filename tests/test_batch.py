"""`matshop batch` on real Dask clusters over a generated library, against the single-set verbs.

The truth for every set is what `matshop apply` (or `matshop export`) writes
for that one set: batch must write the same bytes, all-or-nothing per set,
with a corrupt set reported and the others done.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from batch_library import BROKEN_SET, GOOD_SETS, make_library

import matshop
from matshop.batch import load_recipe, run_batch
from matshop.batch.task import ATTEMPTS_DIR
from matshop.cli import main
from matshop.errors import MatshopError
from matshop.io.images import write_image

ROOT = Path(__file__).resolve().parents[1]
SIZE = 32

RECIPE = """
[[ops]]
op = "blur"
sigma_px = 1.5
params = ["normal", "roughness"]
mask = "ramp.png"

[[ops]]
op = "curves"
points = "0,0;0.5,0.6;1,1"
params = "normal,roughness"
mask = "ramp.png"
"""
#: the same chain in `matshop apply`'s words
APPLY_WORDS = [
    "--op", "blur", "sigma_px=1.5",
    "--op", "curves", "points=0,0;0.5,0.6;1,1",
    "--params", "normal,roughness",
]  # fmt: skip


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def _single(verb: str, library: Path, out_set: str, out: Path) -> list[str]:
    """`matshop VERB IN OUT` naming the one set that batch writes to ``out_set``."""
    folder = library / out_set
    if folder.is_dir():
        return [verb, str(folder), str(out)]
    return [verb, str(folder.parent), str(out), "--material", folder.name]


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = make_library(tmp_path_factory.mktemp("batch") / "library", SIZE)
    ramp = np.linspace(0, 1, SIZE, dtype=np.float32)[None, :].repeat(SIZE, axis=0)
    write_image(root.parent / "ramp.png", ramp[..., None], bit_depth="uint16")
    (root.parent / "recipe.toml").write_text(RECIPE)
    return root


@pytest.fixture(scope="module")
def truth(library: Path) -> dict[str, dict[str, bytes]]:
    """What `matshop apply` writes for each good set, one set per command."""
    expected = {}
    for out_set in GOOD_SETS:
        out = library.parent / "apply" / out_set
        argv = [*_single("apply", library, out_set, out), *APPLY_WORDS]
        assert main([*argv, "--mask", str(library.parent / "ramp.png")]) == 0
        expected[out_set] = _files(out)
    return expected


@pytest.fixture(scope="module")
def cluster() -> str:
    """A real LocalCluster of two worker processes on 127.0.0.1, shared by the tests."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as local:
        yield local.scheduler_address


def _check_outputs(out: Path, truth: dict[str, dict[str, bytes]]) -> None:
    for out_set, files in truth.items():
        assert _files(out / out_set) == files, out_set
    assert not (out / BROKEN_SET).exists()  # all-or-nothing: nothing of the corrupt set
    assert not (out / ATTEMPTS_DIR).exists()
    assert not list(out.rglob(".matshop-staging-*"))  # nothing half-written left behind


def test_cli_batch_equals_apply_per_set(library: Path, truth, tmp_path: Path, capsys) -> None:
    before = _tree(library.parent)
    out = tmp_path / "out"
    code = main(
        ["batch", str(library.parent / "recipe.toml"), str(library), str(out), "--workers", "2"]
    )
    assert code == 1  # one corrupt set
    _check_outputs(out, truth)
    rows = [json.loads(line) for line in (out / "batch-report.jsonl").read_text().splitlines()]
    assert len(rows) == len(GOOD_SETS) + 1
    by_output = {Path(r["output"]).relative_to(out).as_posix(): r for r in rows}
    assert {k for k, r in by_output.items() if r["status"] == "ok"} == set(GOOD_SETS)
    broken = by_output[BROKEN_SET]
    assert broken["status"] == "failed" and "Broken001_1K-PNG_Color.png" in broken["error"]
    assert "\n" not in broken["error"] and broken["outputs"] == []
    for out_set in GOOD_SETS:
        written = sorted(Path(p).name for p in by_output[out_set]["outputs"])
        assert written == sorted(truth[out_set])
    err = capsys.readouterr().err
    assert "Broken001" in err and "Traceback" not in err
    assert _tree(library.parent) == before  # nothing written beside the library


def test_resume_runs_only_what_is_missing(library: Path, truth, cluster: str, tmp_path) -> None:
    out = tmp_path / "out"
    recipe = library.parent / "recipe.toml"
    first = run_batch(recipe, library, out, scheduler=cluster)
    assert first.exit_status == 1 and first.count("ok") == len(GOOD_SETS)
    victim = out / GOOD_SETS[0]
    next(victim.iterdir()).unlink()  # one file of one set lost since
    again = run_batch(recipe, library, out, scheduler=cluster, resume=True, force=True)
    ran = {
        Path(r["output"]).relative_to(out).as_posix()
        for r in again.rows
        if r["status"] != "skipped"
    }
    assert ran == {GOOD_SETS[0], BROKEN_SET}
    assert again.count("skipped") == len(GOOD_SETS) - 1
    _check_outputs(out, truth)
    lines = (out / "batch-report.jsonl").read_text().splitlines()
    assert len(lines) == len(GOOD_SETS) + 1 + 2  # resume appends


def test_pattern_and_export_recipe_equal_export_verb(library: Path, cluster: str, tmp_path) -> None:
    recipe = tmp_path / "export.toml"
    recipe.write_text('[export]\npreset = "gltf"\nsize = 16\n')
    out = tmp_path / "out"
    # the Python API's front door: the package is callable
    report = matshop.batch(recipe, [library], out, scheduler=cluster, pattern="materialx/*")
    assert report.exit_status == 0 and report.count("ok") == 2
    for out_set in ("materialx/chess_set/king_black", "materialx/chess_set/king_white"):
        single = tmp_path / "single" / out_set
        argv = [*_single("export", library, out_set, single), "--preset", "gltf"]
        assert main([*argv, "--size", "16"]) == 0
        assert _files(out / out_set) == _files(single)
    assert sorted(p.name for p in out.iterdir()) == ["batch-report.jsonl", "materialx"]


def test_hostile_folder_names_stay_inside_out(tmp_path: Path, cluster: str) -> None:
    lib = tmp_path / "lib"
    make_library(tmp_path / "src", 8)
    (lib / "Q:\\..\\evil?" / " *name*").mkdir(parents=True)
    for f in (tmp_path / "src" / "polyhaven" / "rock_wall_02").iterdir():
        (lib / "Q:\\..\\evil?" / " *name*" / f.name).write_bytes(f.read_bytes())
    recipe = tmp_path / "r.toml"
    recipe.write_text('[[ops]]\nop = "scale"\nfactor = 0.5\n')
    out = tmp_path / "out"
    report = run_batch(recipe, lib, out, scheduler=cluster)
    assert report.exit_status == 0
    written = [p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()]
    assert sorted(written) == sorted(
        ["batch-report.jsonl"]
        + [f"Q_.._evil/name/rock_wall_02_{t}.png" for t in ("basecolor", "normal_gl", "roughness")]
    )


BAD_RECIPES = [
    ('[[ops]]\nop = "blurr"\n', "ops[1] (blurr): unknown op 'blurr'"),
    ('[[ops]]\nop = "blur"\nsigma_px = -3\n', "ops[1] (blur): blur: sigma_px=-3 is outside"),
    ('[[ops]]\nop = "blur"\nsigma_py = 3\n', "unknown parameter 'sigma_py'"),
    ('[[ops]]\nop = "scale"\n[[ops]]\nop = "blur"\nborder = "mirror"\n', "ops[2] (blur)"),
    ('[[ops]]\nop = "curves"\npoints = "0,0;0.5"\n', "ops[1] (curves)"),
    ('[[ops]]\nop = "blur"\nmask = "nope.png"\n', "ops[1].mask: 'nope.png' not found"),
    ('[[ops]]\nop = "blur"\nparams = ["roughnes"]\n', "ops[1].params: no parameter 'roughnes'"),
    ('[[ops]]\nop = "blur"\n[export]\npreset = "unity"\n', "export.preset: unknown preset"),
    ('[[ops]]\nop = "blur"\n[export]\npreset = "gltf"\nsize = 1000\n', "export.size: a power"),
    ('[[opps]]\nop = "blur"\n', "opps: unknown key"),
    ('[[ops]\nop = "blur"\n', "not a TOML recipe"),
    ("", "nothing to do"),
]


@pytest.mark.parametrize(("text", "words"), BAD_RECIPES)
def test_bad_recipe_is_one_line_exit_2_before_any_work(
    text: str, words: str, library: Path, tmp_path: Path, capsys
) -> None:
    recipe = tmp_path / "bad.toml"
    recipe.write_text(text)
    out = tmp_path / "out"
    assert main(["batch", str(recipe), str(library), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(recipe) in err and words in err, err
    assert not out.exists()


def test_bad_usage_exits_2(library: Path, tmp_path: Path, capsys) -> None:
    recipe = tmp_path / "r.toml"
    recipe.write_text('[[ops]]\nop = "scale"\n')
    assert main(["batch", str(recipe), str(library)]) == 2  # no OUT
    assert main(["batch", str(recipe), str(tmp_path / "nothing"), str(tmp_path / "o")]) == 2
    assert main(["batch", str(recipe), str(library), str(tmp_path / "o"), "--pattern", "zz*"]) == 2
    assert main(["batch", str(recipe), str(library), str(tmp_path / "o"), "--size", "64"]) == 2
    assert not (tmp_path / "o").exists()
    assert "Traceback" not in capsys.readouterr().err


def test_recipe_values_in_cli_words_and_toml_types_agree(tmp_path: Path) -> None:
    a = tmp_path / "a.toml"
    a.write_text('[[ops]]\nop = "curves"\npoints = "0,0;0.5,0.6;1,1"\n')
    b = tmp_path / "b.toml"
    b.write_text('[[ops]]\nop = "curves"\npoints = [[0, 0], [0.5, 0.6], [1, 1]]\n')
    assert load_recipe(a).steps[0].op == load_recipe(b).steps[0].op == "curves"
    points_a = load_recipe(a).steps[0].values["points"]
    points_b = load_recipe(b).steps[0].values["points"]
    assert [tuple(map(float, p)) for p in points_a] == [tuple(map(float, p)) for p in points_b]
    with pytest.raises(MatshopError, match="a.toml"):
        a.write_text('[[ops]]\nop = "curves"\npoints = "0,0;x,1"\n')
        load_recipe(a)


def _start(args: list[str], env: dict[str, str]) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_" + args[0], *args[1:]],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip


def test_real_scheduler_and_workers_survive_a_killed_worker(library: Path, truth, tmp_path) -> None:
    """`dask scheduler` + two `dask worker` processes; one worker is killed mid-task."""
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    )
    file = tmp_path / "scheduler.json"
    scheduler = _start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                        "--scheduler-file", str(file)], env)  # fmt: skip
    workers = []
    try:
        deadline = time.monotonic() + 60
        while not file.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        address = json.loads(file.read_text())["address"]
        for _ in range(2):
            workers.append(_start(["worker", address, "--nthreads", "1", "--no-nanny",
                                   "--no-dashboard", "--host", "127.0.0.1"], env))  # fmt: skip
        from distributed import Client

        with Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=60)
        out = tmp_path / "out"
        result = {}
        runner = threading.Thread(
            target=lambda: result.setdefault(
                "report", run_batch(library.parent / "recipe.toml", library, out, scheduler=address)
            )
        )
        runner.start()
        # a task notes its worker's pid when it starts: kill the first worker seen working
        victim = None
        give_up = time.monotonic() + 120  # a batch that hangs ends the polling
        while victim is None and runner.is_alive() and time.monotonic() < give_up:
            for marker in (
                (out / ATTEMPTS_DIR).glob("*.starts") if (out / ATTEMPTS_DIR).exists() else ()
            ):
                pids = {int(p) for p in marker.read_text().split()}
                hits = [w for w in workers if w.pid in pids]
                if hits:
                    victim = hits[0]
                    break
            time.sleep(0.005)
        assert victim is not None, "the batch ended before a worker could be killed"
        victim.send_signal(signal.SIGKILL)
        runner.join(timeout=120)
        report = result["report"]
    finally:
        for p in [*workers, scheduler]:
            p.kill()
            p.wait(timeout=30)
    assert report.count("ok") == len(GOOD_SETS) and report.count("failed") == 1
    assert max(r.get("attempt", 1) for r in report.rows) >= 2  # Dask ran a lost task again
    _check_outputs(out, truth)


def _look_project(path: Path, library: Path) -> dict[str, float]:
    """A look made on the 32x32 Poly Haven set: values a test can predict at any size.

    Bottom to top: a fill of roughness 0.8 at opacity 0.5 through a mask showing the
    left half; a scale filter halving base color (edit space); a paint layer setting
    roughness 0.2 over the top half.
    """
    from matshop.io.material_io import load_material
    from matshop.io.project import save_project
    from matshop.layers import Document
    from matshop.layers.tiles import TileGrid

    material, _ = load_material(library / "polyhaven" / "rock_wall_02")
    doc = Document.from_material(material)
    rough = doc.schema.edit_slices["roughness"]
    fill_value = np.zeros(doc.channels, np.float32)
    fill_value[rough] = 0.8**2  # GGX edit space: alpha = r^2 (DESIGN.md section 3)
    fill = doc.new_fill_layer("wear", value=fill_value, parameters=["roughness"], opacity=0.5)
    left = np.zeros((SIZE, SIZE), np.float32)
    left[:, : SIZE // 2] = 1.0
    fill.mask = doc.new_mask(array=left)
    doc.insert_layer(fill)
    doc.insert_layer(
        doc.new_filter_layer("scale", op_params={"factor": 0.5}, parameters=["base_color"])
    )
    paint = doc.new_paint_layer("polish", parameters=["roughness"])
    pixels = np.zeros((SIZE, SIZE, doc.channels + 1), np.float32)
    pixels[: SIZE // 2, :, rough] = 0.2**2
    pixels[: SIZE // 2, :, -1] = 1.0
    paint.pixels = TileGrid.from_array(pixels, doc.layout)
    doc.insert_layer(paint)
    save_project(doc, path)


@pytest.mark.parametrize("size", [16, 64])
def test_matshop_look_applies_to_sets_of_other_sizes(
    library: Path, cluster: str, tmp_path: Path, size: int
) -> None:
    from matshop.io.material_io import load_material

    look = tmp_path / "look.matshop"
    _look_project(look, library)
    other = make_library(tmp_path / "lib", size)
    out = tmp_path / "out"
    report = run_batch(look, other, out, scheduler=cluster, pattern="polyhaven/*")
    assert report.exit_status == 0, report.failed
    source, _ = load_material(other / "polyhaven" / "rock_wall_02")
    result, _ = load_material(out / "polyhaven" / "rock_wall_02")
    assert result.size == (size, size)
    # the prediction, composited by hand in edit space
    edit = source.to_edit()
    data = edit.data.copy()
    rough, color = edit.schema.edit_slices["roughness"], edit.schema.edit_slices["base_color"]
    half = size // 2
    data[half:, :half, rough] = 0.5 * data[half:, :half, rough] + 0.5 * 0.8**2
    data[..., color] *= 0.5
    data[:half, :, rough] = 0.2**2
    expected = type(edit)(edit.name, edit.schema, data, edit.sources).to_physical()
    # away from the mask's and the paint's edges, which resampling softens (the
    # image border too: textures tile, so the resampling wraps around)
    keep = np.zeros((size, size), bool)
    keep[2:-2, 2:-2] = True
    keep[half - 2 : half + 2, :] = False
    keep[:, half - 2 : half + 2] = False
    for name in ("base_color", "roughness"):
        diff = np.abs(result.maps[name] - expected.maps[name])[keep]
        assert diff.max() <= 1.0 / 255 + 1e-6, name
    assert np.allclose(result.maps["normal"], source.maps["normal"], atol=2 / 255)


def test_look_without_layers_is_refused(library: Path, tmp_path: Path, capsys) -> None:
    from matshop.io.material_io import load_material
    from matshop.io.project import save_project
    from matshop.layers import Document

    material, _ = load_material(library / "polyhaven" / "rock_wall_02")
    save_project(Document.from_material(material), tmp_path / "empty.matshop")
    out = tmp_path / "out"
    assert main(["batch", str(tmp_path / "empty.matshop"), str(library), str(out)]) == 2
    assert "empty.matshop: the look has no layers above its base" in capsys.readouterr().err
    assert not out.exists()
