"""The results tables of the README and docs/ are what their commands write now.

Each table sits between markers with its command (scripts/paste_results.py); the cheap ones
are rerun here and compared with the docs, the scorecards (a minute or more of CPU) in the
slow tests. A failure means: rerun ``python scripts/paste_results.py NAME --run``.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
import yaml

from baselines.cli.main import main
from tests.script_module import load_script

ROOT = Path(__file__).resolve().parents[1]


LEADERBOARDS = ("threerod-leaderboard", "stock-leaderboard")
"""The blocks ``sgc paste`` writes (``sgc benchmark`` sweeps, hours each)."""


def _paste():
    return load_script("paste_results")


paste = _paste()


def _pasted(name: str) -> list[tuple[Path, str]]:
    """Every (document, block text) holding the block ``name``."""
    begin, _ = paste.markers(name)
    return [(doc, paste.block(doc.read_text(), name, str(doc))) for doc in paste.documents()
            if begin in doc.read_text()]  # fmt: skip


def _rerun(name: str, out: Path) -> str:
    """Run the block's command with its output under ``out``; the block it gives."""
    argv = shlex.split(paste.RESULTS[name].command)[1:]
    argv[argv.index("--out") + 1] = str(out)
    if argv[0] == "demo":
        argv.append("--no-video")
    assert main(argv) == 0
    return paste.body_from(name, out / Path(paste.RESULTS[name].output).name)


def test_every_marker_pair_in_the_docs_is_a_known_table() -> None:
    names = set(paste.RESULTS) | {paste.SUMMARY}
    for doc in paste.documents():
        for name in re.findall(r"<!-- ([\w-]+):begin -->", doc.read_text()):
            known = name in names or name in LEADERBOARDS
            assert known, f"{doc.name}: block {name!r} has no command in paste_results.py"


@pytest.mark.parametrize("name", ["paper-rule", "demo", "demo-learned"])
def test_cheap_tables_are_what_their_commands_write(name: str, tmp_path: Path) -> None:
    where = _pasted(name)
    assert where, f"no document holds the {name} table"
    expected = _rerun(name, tmp_path / name)
    for doc, text in where:
        assert text == expected, f"{doc.relative_to(ROOT)}: the {name} table is stale"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["scorecard", "smoothness"])
def test_scorecards_are_what_their_commands_write(name: str, tmp_path: Path) -> None:
    expected = _rerun(name, tmp_path / name)
    for doc, text in _pasted(name):
        assert text == expected, f"{doc.relative_to(ROOT)}: the {name} table is stale"


def test_readme_summary_is_the_results_leaderboard() -> None:
    ((readme, text),) = _pasted(paste.SUMMARY)
    assert readme.name == "README.md"
    assert text == paste.summary_block((ROOT / paste.SUMMARY_SOURCE).read_text())
    assert "| `SGCRod-v1` | `zoo-ppo-300s` | no | 10 | 167 | 0.94 [0.73, 0.98] |" in text


def test_every_leaderboard_is_in_results_once_with_its_reproduce_line() -> None:
    """docs/results.md holds each leaderboard block once, each with the command that wrote
    it; no other document holds one."""
    results = ROOT / "docs" / "results.md"
    for name in LEADERBOARDS:
        body = paste.block(results.read_text(), name, str(results))
        assert body.startswith("Reproduce: `sgc benchmark --recipes benchmarks/recipes.yml "), name
        for doc in paste.documents():
            if doc != results:
                assert f"<!-- {name}:begin -->" not in doc.read_text(), (doc, name)


def test_a_table_needs_its_markers_once() -> None:
    with pytest.raises(ValueError, match=r"README\.md: needs exactly one <!-- demo:begin -->"):
        paste.replace("no markers", "demo", "x", "README.md")
    doc = "a\n<!-- demo:begin -->\nold\n<!-- demo:end -->\nb"
    assert (
        paste.replace(doc, "demo", "new", "d")
        == "a\n<!-- demo:begin -->\nnew\n<!-- demo:end -->\nb"
    )


def test_the_stock_leaderboard_has_a_row_for_every_budget_recipe() -> None:
    """Every family at equal wall clock: each budget recipe of benchmarks/recipes.yml has its
    10-seed row in the pasted leaderboard, and its Reproduce line names them all."""
    recipes = yaml.safe_load((ROOT / "benchmarks" / "recipes.yml").read_text())["recipes"]
    budgets = [r["name"] for r in recipes if r.get("time_budget_s")]
    body = paste.block((ROOT / "docs" / "results.md").read_text(), "stock-leaderboard", "results")
    rows = {line.split("|")[1].strip(): line.split("|")[4].strip()
            for line in body.splitlines() if line.startswith("| ") and "---" not in line
            and not line.startswith("| recipe ")}  # fmt: skip
    assert sorted(rows) == sorted(budgets) and set(rows.values()) == {"10"}
    only = re.search(r"--only (\S+)", body)
    assert only is not None and sorted(only.group(1).split(",")) == sorted(budgets)
