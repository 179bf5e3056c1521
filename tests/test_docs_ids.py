"""The README and docs/ name only registered ids: an old id lives in CHANGELOG.md alone (its
migration table), which docs/changelog.md includes rather than repeats."""

from __future__ import annotations

import re
from pathlib import Path

import sgc_env

ROOT = Path(__file__).resolve().parents[1]
ID = re.compile(r"\bSGC[A-Za-z]+-v\d+\b")


def test_readme_and_docs_name_registered_ids_only() -> None:
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    unregistered = [
        f"{page.relative_to(ROOT)}:{number}: {name}"
        for page in pages
        for number, line in enumerate(page.read_text().splitlines(), 1)
        for name in ID.findall(line)
        if name not in sgc_env.ENV_IDS
    ]
    assert unregistered == []
    changelog = (ROOT / "docs" / "changelog.md").read_text().strip()
    assert changelog == "```{include} ../CHANGELOG.md\n```"


def test_the_pattern_finds_an_old_id() -> None:
    assert ID.findall("fly `SGCRod-v0` or SGCRod-v1.") == ["SGCRod-v0", "SGCRod-v1"]
