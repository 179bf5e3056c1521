"""``sgc paste``: the leaderboard lands in every document, or in none with one clean line."""

from __future__ import annotations

from pathlib import Path

import pytest

from baselines.cli.main import main

BOARD = "# Benchmark leaderboard\n\nReproduce: `sgc benchmark --only {only}`\n\n## R-v1\n\n{rows}\n"
HEAD = "| recipe | algo |\n|---|---|\n"


def test_paste_and_merge_write_every_document(tmp_path: Path) -> None:
    board, docs = tmp_path / "leaderboard.md", [tmp_path / "a.md", tmp_path / "b.md"]
    board.write_text(BOARD.format(only="x", rows=HEAD + "| x | ppo |"))
    for doc in docs:
        doc.write_text("top\n<!-- board:begin -->\nold\n<!-- board:end -->\nend\n")
    assert main(["paste", str(board), *map(str, docs), "--marker", "board"]) == 0
    assert all("| x | ppo |" in doc.read_text() and "old" not in doc.read_text() for doc in docs)
    board.write_text(BOARD.format(only="y", rows=HEAD + "| y | sac |"))
    assert main(["paste", str(board), str(docs[0]), "--marker", "board", "--merge"]) == 0
    text = docs[0].read_text()
    assert "--only x,y" in text and text.index("| x | ppo |") < text.index("| y | sac |")
    assert text.startswith("top\n") and text.endswith("end\n")


def test_a_bad_document_writes_none(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    board, good, bad = tmp_path / "leaderboard.md", tmp_path / "good.md", tmp_path / "bad.md"
    board.write_text(BOARD.format(only="x", rows=HEAD + "| x | ppo |"))
    good.write_text("<!-- board:begin -->\nold\n<!-- board:end -->\n")
    bad.write_text("no markers\n")
    assert main(["paste", str(board), str(good), str(bad), "--marker", "board"]) == 2
    assert good.read_text() == "<!-- board:begin -->\nold\n<!-- board:end -->\n"
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.md: needs exactly one <!-- board:begin -->" in err[0]
