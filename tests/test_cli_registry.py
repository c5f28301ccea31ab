"""The verb registry: `matshop --help` lists every verb without importing one, and
every verb named there parses its own options and dispatches through ``args.run``."""

from __future__ import annotations

import subprocess
import sys

import pytest

from matshop.cli import build_parser, main
from matshop.cli.registry import VERBS

_PROBE = """
import contextlib, io, sys
from matshop.cli import main
with contextlib.redirect_stdout(io.StringIO()) as out:
    try:
        main(["--help"])
    except SystemExit:
        pass
verbs = sorted(m for m in sys.modules if m.startswith("matshop.cli.verbs."))
print(len(verbs), "numpy" in sys.modules, out.getvalue().count("\\n"))
"""


def test_help_lists_the_verbs_without_importing_them_or_numpy() -> None:
    result = subprocess.run(
        [sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=120, check=True
    )
    verbs_imported, numpy, lines = result.stdout.split()
    assert verbs_imported == "0" and numpy == "False" and int(lines) > len(VERBS)


@pytest.mark.parametrize("verb", list(VERBS))
def test_every_verb_has_its_help(verb: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as done:
        main([verb, "--help"])
    assert done.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: matshop {verb}")


@pytest.mark.parametrize(
    ("argv", "handler"),
    [
        (["info", "x"], "matshop.cli.verbs.info.run"),
        (["layer", "add", "p.matshop", "paint"], "matshop.cli.verbs.layer.cmd_layer_add"),
        (["layer", "list", "p.matshop"], "matshop.cli.verbs.layer.cmd_layer_list"),
        (["export", "--list-presets"], "matshop.cli.verbs.export.run"),
    ],
)
def test_one_dispatch_path(argv: list[str], handler: str) -> None:
    run = build_parser(argv).parse_args(argv).run
    assert f"{run.__module__}.{run.__name__}" == handler
