"""Model cards: one beside every shipped model, holding the manifest's facts and a fresh run."""

from __future__ import annotations

import re
from pathlib import Path

from baselines.cli.main import main
from baselines.zoo.cards import card_markdown, recipe
from baselines.zoo.manifest import CHECKPOINTS, load_manifest

ROOT = Path(__file__).resolve().parents[3]
SECTIONS = ("**Env**", "**Algorithm**", "**Recipe**", "**Training seed**",
            "**Training steps**", "**Wall clock**", "## Held-out results", "sgc evaluate --env",
            "## One episode")  # fmt: skip


def test_every_shipped_model_has_a_card_with_the_manifest_facts():
    for entry in load_manifest():
        stem = entry["file"][: -len(".zip")]
        card = (CHECKPOINTS / f"{stem}.md").read_text()
        for section in SECTIONS:
            assert section in card, (stem, section)
        assert entry["command"] in card and entry["env_id"] in card
        result = entry["result"]
        assert f"| {result['goals_met']}/{result['n_goals']} |" in card
        gif = re.search(r"\]\((\.\./\.\./docs/images/model_[^)]+\.gif)\)", card)
        assert gif and (CHECKPOINTS / gif.group(1)).resolve().is_file(), stem


def test_card_reports_its_own_evaluation_apart_from_the_manifest():
    entry = {"file": "ppo_x_SGCPoint-v1.zip", "env_id": "SGCPoint-v1", "algo": "ppo",
             "demonstrations": False, "timesteps": 300000, "seed": 2, "wall_time_s": 489.7,
             "command": "sgc train --hyperparams benchmarks/hyperparams/ppo_schedule",
             "result": {"episodes": 50, "seed": 20000, "n_goals": 150, "goals_met": 150,
                        "success_rate": 1.0, "position_error_mean": 0.0037,
                        "position_error_max": 0.01, "orientation_error_mean": None,
                        "terminated": 0}}  # fmt: skip
    fresh = {**entry["result"], "episodes": 10, "goals_met": 29, "n_goals": 30}
    card = card_markdown(entry, fresh, "model.gif", "a test machine", 3.0)
    own, shipped = card.split("Measured when the model was shipped")
    assert "| 29/30 |" in own and "seeds 20000 to 20009" in own and "a test machine" in own
    assert "| 150/150 |" in shipped and "seeds 20000 to 20049" in shipped
    assert "--episodes 10 --seed 20000" in card
    assert recipe(entry) == "RL from scratch, hyperparameters `ppo_schedule`"


def test_card_command_rejects_an_unknown_model(capsys):
    assert main(["card", "no_such_model", "--no-gif"]) == 2
    assert "no shipped model" in capsys.readouterr().err
