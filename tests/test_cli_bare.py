"""A bare ``matshop`` starts the editor where a window can open, else prints its help."""

from __future__ import annotations

import pytest

import matshop.cli as cli


def test_bare_matshop_starts_the_editor_with_a_display(monkeypatch) -> None:
    pytest.importorskip("PySide6")
    import matshop.app.launch as launch

    started = []
    monkeypatch.setattr(launch, "start", lambda *a, **k: started.append(a) or 0)
    monkeypatch.setattr(cli, "_has_display", lambda: True)
    assert cli.main([]) == 0
    assert started == [()]


def test_bare_matshop_without_a_display_prints_help(monkeypatch, capsys) -> None:
    monkeypatch.setattr(cli, "_has_display", lambda: False)
    assert cli.main([]) == cli.EXIT_USAGE
    out = capsys.readouterr().out
    assert "usage: matshop" in out and "export" in out and "paint" in out


def test_spaces_lists_defaults_and_aliases_in_columns(capsys) -> None:
    from matshop.cli import main

    assert main(["spaces"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["space", "channels", "default", "for", "meaning"]
    rows = {line.split()[0]: line for line in lines[1:]}
    assert rows["ggx_median"].endswith("alias of ggx")
    assert "roughness" in rows["ggx"] and "base_color" in rows["srgb"]
    assert "alias" not in rows["ggx_alpha"]
    # aligned: every row's meaning starts in the same column as the header's
    column = lines[0].index("meaning")
    assert all(line[column - 1] == " " and line[column] != " " for line in lines)
