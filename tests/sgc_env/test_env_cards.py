"""Env cards: one per registered id, with every Gymnasium section, and the doc is current."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym

import sgc_env
from sgc_env.env_cards import CARDS, card_markdown, gif_path, pages

ROOT = Path(__file__).resolve().parents[2]
SECTIONS = ("Description", "Action Space", "Observation Space", "Rewards", "Starting State",
            "Episode End", "Arguments", "Version History")  # fmt: skip


def test_every_registered_id_has_one_card_at_its_latest_version():
    assert sorted(card.env_id for card in CARDS) == sorted(sgc_env.ENV_IDS)
    for card in CARDS:
        assert gym.spec(card.env_id).name == card.name


def test_every_card_has_every_section_and_an_existing_gif():
    for card in CARDS:
        text = card_markdown(card)
        for section in SECTIONS:
            assert f"#### {section}\n" in text, (card.env_id, section)
        assert "- v0: " in text
        shown = card.gif_of or card.env_id
        gif = ROOT / "docs" / gif_path(shown)
        assert gif.is_file() and gif.stat().st_size < 400_000, gif


def test_cards_read_spaces_from_the_envs():
    rod = card_markdown(next(c for c in CARDS if c.env_id == "SGCRod-v0"))
    assert "`Box(-1, 1, (6,), float32)`" in rod and "torque" in rod
    goal = card_markdown(next(c for c in CARDS if c.env_id == "SGCPointGoal-v0"))
    assert "`Dict`" in goal and "compute_reward" in goal


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
