"""scripts/paste_leaderboard.py: a leaderboard lands between its own marker pair only."""

from __future__ import annotations

import pytest

from tests.script_module import load_script


def _paste_module():
    return load_script("paste_leaderboard")


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


def test_each_marker_pair_takes_its_own_leaderboard() -> None:
    paste = _paste_module()
    body = paste.leaderboard_body("# Leaderboard\n\n## SGCRod-v1\n\n| a |\n")
    assert body == "### SGCRod-v1\n\n| a |"
    out = paste.paste(DOC, body, "doc", "budget-leaderboard")
    assert "old budget table" not in out and "old steps table" in out
    assert out.count("### SGCRod-v1") == 1
    assert out.index("### SGCRod-v1") > out.index("middle")
    out = paste.paste(out, "steps", "doc")  # the default pair
    assert "old steps table" not in out and "### SGCRod-v1" in out


def test_a_missing_or_doubled_marker_is_an_error_naming_the_document() -> None:
    paste = _paste_module()
    with pytest.raises(ValueError, match=r"README\.md: needs exactly one <!-- other:begin -->"):
        paste.paste(DOC, "x", "README.md", "other")
    with pytest.raises(ValueError, match="needs exactly one"):
        paste.paste(DOC + DOC, "x", "README.md")
    with pytest.raises(ValueError, match="no '# ' title line"):
        paste.leaderboard_body("| a |")
