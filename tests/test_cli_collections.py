"""While a verb runs, the cyclic collector runs rarely (its start-up objects live until
exit); the caller's thresholds come back afterwards, also when the verb fails."""

from __future__ import annotations

import argparse
import gc
from pathlib import Path

import pytest

import matshop.cli.verbs.info as info
from matshop.cli import main

SAMPLE = Path(__file__).resolve().parents[1] / "resources" / "sample"


@pytest.mark.parametrize("target", [SAMPLE, SAMPLE / "absent"])
def test_a_verb_runs_with_rare_collections_and_restores_them(
    target: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = []
    real = info.run

    def run(args: argparse.Namespace) -> int:
        seen.append(gc.get_threshold())
        return real(args)

    monkeypatch.setattr(info, "run", run)
    before = gc.get_threshold()
    assert main(["info", str(target)]) == (0 if target.exists() else 2)
    assert seen[0][0] == 50_000 and seen[0][1:] == before[1:]
    assert gc.get_threshold() == before
