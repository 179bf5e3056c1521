"""baselines.benchmark.paste: a leaderboard lands between its own marker pair only, and a merge
gives the leaderboard the union of two runs would have written."""

from __future__ import annotations

import pytest

from baselines.benchmark.paste import block, leaderboard_body, merge, replace

DOC = """intro
<!-- leaderboard:begin -->
old steps table
<!-- leaderboard:end -->
middle
<!-- budget-leaderboard:begin -->
old budget table
<!-- budget-leaderboard:end -->
outro
"""

HEAD = "| recipe | algo |\n|---|---|"


def _board(only: str, tables: dict[str, list[str]], workers: int = 2, text: str = "text") -> str:
    command = f"sgc benchmark --only {only} --seeds 10 --workers {workers}"
    lines = ["# Benchmark leaderboard", "", f"Reproduce: `{command}`", "", text]
    for env_id, rows in tables.items():
        lines += ["", f"## {env_id}", "", HEAD, *(f"| {r} |" for r in rows)]
    return "\n".join(lines) + "\n"


def test_each_marker_pair_takes_its_own_leaderboard() -> None:
    body = leaderboard_body("# Leaderboard\n\n## SGCRod-v1\n\n| a |\n")
    assert body == "### SGCRod-v1\n\n| a |"
    out = replace(DOC, "budget-leaderboard", body, "doc")
    assert "old budget table" not in out and "old steps table" in out
    assert out.count("### SGCRod-v1") == 1
    assert out.index("### SGCRod-v1") > out.index("middle")
    out = replace(out, "leaderboard", "steps", "doc")
    assert "old steps table" not in out and "### SGCRod-v1" in out
    assert block(out, "leaderboard", "doc") == "steps"


def test_a_missing_or_doubled_marker_is_an_error_naming_the_document() -> None:
    with pytest.raises(ValueError, match=r"README\.md: needs exactly one <!-- other:begin -->"):
        replace(DOC, "other", "x", "README.md")
    with pytest.raises(ValueError, match="needs exactly one"):
        replace(DOC + DOC, "leaderboard", "x", "README.md")
    with pytest.raises(ValueError, match=r"board\.md: not a leaderboard\.md"):
        leaderboard_body("| a |", "board.md")


def test_a_merge_is_the_union_run() -> None:
    pasted = _board("b,d", {"P-v1": ["b | old"], "R-v1": ["d | old"]}, text="old text")
    new = _board("a,d,e", {"R-v1": ["e | new", "d | new"], "Q-v1": ["a | new"]}, workers=1)
    union = _board(
        "b,d,a,e", {"P-v1": ["b | old"], "Q-v1": ["a | new"], "R-v1": ["d | new", "e | new"]},
        workers=1,
    )  # fmt: skip
    merged = merge(leaderboard_body(pasted), leaderboard_body(new), "doc")
    assert merged == leaderboard_body(union)


def test_a_merge_refuses_other_commands_and_other_columns() -> None:
    pasted = leaderboard_body(_board("b", {"P-v1": ["b | x"]}))
    other = _board("a", {"P-v1": ["a | x"]}).replace("--seeds 10", "--seeds 5")
    with pytest.raises(ValueError, match="doc: the leaderboards come from different commands"):
        merge(pasted, leaderboard_body(other), "doc")
    wider = _board("a", {"P-v1": ["a | x"]}).replace(HEAD, "| recipe | algo | x |\n|---|---|---|")
    with pytest.raises(ValueError, match="the P-v1 tables have different columns"):
        merge(pasted, leaderboard_body(wider), "doc")
    with pytest.raises(ValueError, match="no --only list"):
        merge(pasted.replace("--only b ", ""), leaderboard_body(_board("a", {})), "doc")


def test_a_merge_reads_either_spelling_of_only() -> None:
    pasted = leaderboard_body(_board("b", {"P-v1": ["b | old"]}))
    new = leaderboard_body(_board("a", {"P-v1": ["a | new"]}).replace("--only a", "--only=a"))
    merged = merge(pasted, new, "doc")
    assert "`sgc benchmark --only=b,a --seeds 10 --workers 2`" in merged
    assert merged.index("| a | new |") < merged.index("| b | old |")
