"""Env cards: one per registered id, with every Gymnasium section, and the doc is current."""

from __future__ import annotations

import re
from pathlib import Path

import gymnasium as gym
import pytest

import sgc_env
from sgc_env.env_cards import CARDS, card_markdown, gif_path, learner_rows, pages
from sgc_env.envs.learner_view import learner_bounds

ROOT = Path(__file__).resolve().parents[2]
SECTIONS = ("Description", "Action Space", "Observation Space", "Rewards", "Starting State",
            "Episode End", "Arguments", "Version History")  # fmt: skip


def test_every_registered_id_is_a_version_on_its_card():
    """Each card's latest version is registered, and it alone: the registered ids are
    exactly the cards' ids."""
    assert sorted(card.env_id for card in CARDS) == sorted(sgc_env.ENV_IDS)
    registered = [env_id for card in CARDS for env_id in card.registered_ids]
    assert sorted(registered) == sorted(sgc_env.ENV_IDS)
    for card in CARDS:
        assert card.registered_ids == [card.env_id]
        assert gym.spec(card.env_id).name == card.name


def _card(env_id: str) -> str:
    card = next(c for c in CARDS if env_id in c.registered_ids)
    return card_markdown(card, env_id)


def test_every_card_has_every_section_and_an_existing_gif():
    for card in CARDS:
        for env_id in card.registered_ids:
            text = card_markdown(card, env_id)
            for section in SECTIONS:
                assert f"#### {section}\n" in text, (env_id, section)
            assert f"- {env_id.rsplit('-', 1)[1]} (this page): " in text
            assert "(no longer registered)" in text  # the earlier versions, named by version
        gif = ROOT / "docs" / gif_path(card.gif_id)
        assert gif.is_file() and gif.stat().st_size < 400_000, gif


def test_cards_read_spaces_from_the_envs():
    rod = _card("SGCRod-v1")
    assert "`Box(-1, 1, (6,), float32)`" in rod and "torque" in rod
    goal = _card("SGCPointGoal-v1")
    assert "`Dict`" in goal and "compute_reward" in goal


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRodsRandom-v3"])
def test_the_cards_say_which_view_and_reward_they_have(env_id: str):
    """Every id: the learner's table (each entry with its why) and `tracking` by default,
    explained; the planner's view is named as the privileged one; the version history says
    the earlier versions are answered with DeprecatedEnv, naming no earlier id."""
    text = _card(env_id)
    assert "The learner's view" in text and "`position_deviation`" not in text
    assert "| on-schedule error `D - D_sched` | 0 | 3 |" in text
    assert "| what the reward charges |" in text and "time feature" in text
    assert "- `tracking` (default): " in text and "falls at every distance" in text
    assert "`\"planner\"`, the privileged view" in text
    assert "`DeprecatedEnv`" in text
    name = env_id.rsplit("-", 1)[0]
    assert [i for i in re.findall(rf"{name}-v\d+", text) if i != env_id] == []


def test_the_learner_table_matches_the_views_bounds():
    """The table (read from the view's docstring, its one home) puts each entry where the
    view's bounds say its range is: squashed entries within +-3, the course fraction and the
    flags in [0, 1], the times in [-1, 3]."""
    head, *rows = learner_rows()
    assert head[:3] == ["entry", "offset (body 0)", "size"]
    low, high = learner_bounds(1)
    scale = head.index("scale")
    for row in rows:
        at, size = int(row[1]), int(row[2])
        text = row[scale]
        expected = ((-3.0, 3.0) if "squashed" in text else (-1.0, 3.0) if "[-1, 3]" in text
                    else (0.0, 1.0))  # fmt: skip
        for k in range(at, at + size):
            assert (low[k], high[k]) == expected, (row[0], k)


def test_the_env_pages_are_what_the_cards_generate():
    """docs/envs holds one page per id, exactly as ``python -m sgc_env.env_cards --write``
    writes it (rerun it after changing a card or an env's spaces)."""
    folder = ROOT / "docs" / "envs"
    expected = pages()
    assert sorted(p.name for p in folder.glob("*.md")) == sorted(expected)
    for name, text in expected.items():
        assert (folder / name).read_text() == text, f"docs/envs/{name} is stale"


def test_the_model_zoo_page_includes_every_shipped_card():
    """docs/zoo.md includes each card in baselines/checkpoints (a new model needs its line)."""
    zoo = (ROOT / "docs" / "zoo.md").read_text()
    cards = sorted((ROOT / "baselines" / "checkpoints").glob("*.md"))
    assert cards
    for card in cards:
        assert f"```{{include}} ../baselines/checkpoints/{card.name}\n" in zoo, card.name
