"""The shipped recipes file resolves, and scripts/seed_table.py scores finished runs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.script_module import load_script

pytest.importorskip("stable_baselines3")

ROOT = Path(__file__).resolve().parents[3]


def _seed_table():
    return load_script("seed_table")


def test_every_recipe_resolves_on_its_envs() -> None:
    """A recipe whose folder lacks one of its ids (or has a typo) would fail mid-benchmark;
    every recipe runs on registered ids only."""
    import sgc_env
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.benchmark.grid import load_recipes

    recipes = load_recipes(ROOT / "benchmarks" / "recipes.yml")
    assert recipes
    for recipe in recipes:
        assert recipe.envs and set(recipe.envs) <= set(sgc_env.ENV_IDS), recipe.name
        if recipe.hyperparams is None:
            continue
        for env_id in recipe.envs:
            load_hyperparams(recipe.algo, env_id, recipe.hyperparams)


def test_seed_table_scores_a_finished_run(tmp_path: Path) -> None:
    from baselines.agents.train import TrainConfig, train

    hp = tmp_path / "hp"
    hp.mkdir()
    (hp / "ppo.yml").write_text(
        "SGCPoint-v1:\n  n_timesteps: 128\n  policy: MlpPolicy\n  n_envs: 2\n  n_steps: 64\n"
        '  batch_size: 64\n  n_epochs: 1\n  policy_kwargs: "dict(net_arch=[8])"\n'
    )
    run = tmp_path / "run"
    train(TrainConfig("ppo", "SGCPoint-v1", seed=3, timesteps=128, out=run, hyperparams_dir=hp))
    row = _seed_table().seed_row(run, episodes=1, seed=20_000)
    assert row["seed"] == 3 and row["steps"] == 128 and row["env_id"] == "SGCPoint-v1"
    assert row["n_goals"] == 3 and 0 <= row["goals_met"] <= 3
    config = json.loads((run / "config.json").read_text())
    assert row["wall_time_s"] == round(config["wall_time_s"], 1)  # 0.0 where 128 steps are fast
    assert config["wall_time_s"] > 0 and row["result"]["seed"] == 20_000


def test_seed_table_names_a_folder_that_is_not_a_run(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="not a finished run"):
        _seed_table().seed_row(tmp_path, episodes=1, seed=20_000)


def test_seed_table_reads_a_benchmark_score_only_for_the_seeds_asked(tmp_path: Path) -> None:
    """--scored takes the final score of a `sgc benchmark` run's result.json, never a score
    measured on other held-out seeds or episodes."""
    (tmp_path / "final_model.zip").write_bytes(b"")
    (tmp_path / "config.json").write_text(json.dumps({
        "env_id": "SGCRod-v1", "seed": 4, "timesteps": 1000, "wall_time_s": 12.3,
        "learn_time_s": 10.0}))  # fmt: skip
    final = {"goals_met": 121, "n_goals": 150, "success_rate": 121 / 150}
    (tmp_path / "result.json").write_text(json.dumps({
        "spec": {"eval_episodes": 50, "test_seed": 20_000},
        "scores": {"final": final, "best": {"goals_met": 0, "n_goals": 150, "success_rate": 0}}}))
    row = _seed_table().seed_row(tmp_path, episodes=50, seed=20_000, scored=True)
    assert (row["seed"], row["goals_met"], row["wall_time_s"]) == (4, 121, 12.3)
    with pytest.raises(ValueError, match="not 50 from 30000"):
        _seed_table().seed_row(tmp_path, episodes=50, seed=30_000, scored=True)
