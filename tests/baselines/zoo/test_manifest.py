"""Shipped models: the manifest agrees with the folder, and each model evaluates alone."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from baselines.cli import main as cli  # noqa: E402
from baselines.zoo.manifest import (  # noqa: E402
    CHECKPOINTS,
    ENTRY_FIELDS,
    check_manifest,
    load_manifest,
    ship_model,
    steps_trained,
    write_entry,
)

ENTRIES = load_manifest()


def test_manifest_lists_exactly_the_shipped_models() -> None:
    assert ENTRIES, "baselines/checkpoints/manifest.json is missing or empty"
    assert check_manifest() == []
    shipped = [p for p in CHECKPOINTS.iterdir() if p.suffix in (".zip", ".json")]
    assert sum(p.stat().st_size for p in shipped) < 20 * 1024 * 1024


def test_manifest_entries_are_consistent() -> None:
    import sgc_env

    for entry in ENTRIES:
        assert entry["env_id"] in sgc_env.ENV_IDS
        assert entry["algo"] in ("ppo", "sac", "td3", "her")
        steps = [part.strip() for part in entry["command"].split("&&")]  # demos, then train
        assert all(step.startswith("sgc ") for step in steps), entry["command"]
        assert steps[-1].startswith("sgc train") and f"--env {entry['env_id']}" in steps[-1]
        result = entry["result"]
        assert 0 <= result["goals_met"] <= result["n_goals"]
        assert result["success_rate"] == pytest.approx(result["goals_met"] / result["n_goals"])


@pytest.mark.parametrize("entry", ENTRIES, ids=[e["file"] for e in ENTRIES])
def test_shipped_model_evaluates_alone(entry: dict, tmp_path: Path) -> None:
    """`sgc evaluate --policy FILE --env ID` with nothing else; the first held-out episode
    agrees with the recorded result where that result leaves no doubt (all or nothing)."""
    result = entry["result"]
    argv = ["evaluate", "--policy", str(CHECKPOINTS / entry["file"]), "--env", entry["env_id"],
            "--episodes", "1", "--seed", str(result["seed"]), "--no-plots", "--out",
            str(tmp_path)]  # fmt: skip
    assert cli.main(argv) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["n_goals"] > 0
    if result["success_rate"] in (0.0, 1.0):
        assert summary["success_rate"] == result["success_rate"]


def test_manifest_errors_name_the_problem(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="missing"):
        write_entry({"file": "a.zip"}, tmp_path)
    entry = {name: kind() if isinstance(kind, type) else 0.0 for name, kind in ENTRY_FIELDS.items()}
    write_entry({**entry, "file": "a.zip"}, tmp_path)
    (tmp_path / "b.zip").write_bytes(b"")
    assert check_manifest(tmp_path) == [
        f"a.zip: listed, not in {tmp_path}",
        f"b.zip: in {tmp_path}, not listed",
    ]
    (tmp_path / "manifest.json").write_text('[{"file": "a.zip"}]')
    with pytest.raises(ValueError, match="entry 0: missing field"):
        load_manifest(tmp_path)


def test_shipped_model_carries_its_normalisation(tmp_path: Path) -> None:
    """A VecNormalize model shipped by ship_model scores the same alone as in its run."""
    from baselines.agents.train import TrainConfig, train
    from baselines.evaluation.harness import evaluate

    hp = tmp_path / "hp"
    hp.mkdir()
    (hp / "ppo.yml").write_text(
        "SGCPoint-v1:\n  n_timesteps: 128\n  policy: MlpPolicy\n  normalize: true\n"
        "  n_envs: 2\n  n_steps: 64\n  batch_size: 64\n  n_epochs: 1\n"
        '  policy_kwargs: "dict(net_arch=[8])"\n'
    )
    run = tmp_path / "run"
    train(TrainConfig("ppo", "SGCPoint-v1", timesteps=128, out=run, hyperparams_dir=hp,
                      command="sgc train --algo ppo --env SGCPoint-v1"))  # fmt: skip
    folder = tmp_path / "ship"
    folder.mkdir()
    entry = ship_model(run, "tiny", which="final", episodes=1, seed=20_000, folder=folder)
    assert (folder / "tiny.vecnormalize.json").is_file() and check_manifest(folder) == []
    assert entry["demonstrations"] is False and entry["timesteps"] == 128
    alone = folder / "alone"
    alone.mkdir()
    shutil.copy(folder / "tiny.zip", alone / "tiny.zip")  # without its statistics
    in_run = evaluate(str(run / "final_model.zip"), "SGCPoint-v1", 1, 20_000).summary
    shipped = evaluate(str(folder / "tiny.zip"), "SGCPoint-v1", 1, 20_000).summary
    bare = evaluate(str(alone / "tiny.zip"), "SGCPoint-v1", 1, 20_000).summary
    assert shipped["position_error_mean"] == in_run["position_error_mean"]
    assert bare["position_error_mean"] != in_run["position_error_mean"]


def test_a_budget_run_ships_the_steps_it_learned_from_not_its_cap() -> None:
    budget = {"timesteps": 500_000, "steps_reached": 503_808, "steps_learned": 503_808}
    assert steps_trained(budget) == 503_808
    cut = {"timesteps": 10_000_000, "steps_reached": 36_864, "steps_learned": 32_768}
    assert steps_trained(cut) == 32_768
    assert steps_trained({"timesteps": 1_253_376}) == 1_253_376  # a run without a budget
    assert steps_trained({"timesteps": 0}) == 0  # behaviour cloning only
