"""The ladder tables in the docs are what ``python -m sgc_env.ladder`` prints from the code."""

from __future__ import annotations

from pathlib import Path

import sgc_env
from sgc_env import ladder

ROOT = Path(__file__).resolve().parents[2]


def test_every_registered_id_is_on_the_ladder_once():
    ids = [rung.env_id for rung in ladder.LADDER]
    assert sorted(ids) == sorted(sgc_env.ENV_IDS)


def test_environments_doc_holds_the_generated_ladder():
    assert ladder.markdown() in (ROOT / "docs" / "environments.md").read_text()


def test_readme_holds_the_generated_short_ladder():
    assert ladder.short_markdown() in (ROOT / "README.md").read_text()


def test_the_ladder_reads_spaces_from_the_envs():
    table = ladder.markdown()
    assert "| `SGCThreeRodsRandom-v3` | 3 rods | Box (148,) | Box (18,) |" in table
    assert "| `SGCIntercept-v1` | 1 sphere | Box (50,) | Box (3,) | 2 | fixed |" in table
