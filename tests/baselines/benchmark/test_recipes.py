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


@pytest.mark.parametrize("name", ["recipes.yml", "archive/recipes.yml"])
def test_every_recipe_resolves_on_its_envs(name: str) -> None:
    """A recipe whose folder lacks one of its ids (or has a typo) would fail mid-benchmark."""
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.benchmark.grid import load_recipes

    recipes = load_recipes(ROOT / "benchmarks" / name)
    fast = [r for r in recipes if r.name.startswith("ppo-fast")]
    assert bool(fast) == name.startswith("archive"), "the ppo-fast recipes are archived"
    for recipe in recipes:
        if recipe.hyperparams is None:
            continue
        for env_id in recipe.envs:
            hp = load_hyperparams(recipe.algo, env_id, recipe.hyperparams)
            if recipe in fast:  # more sub-envs than ppo-schedule's 8: the point of these
                assert hp.n_envs >= 16 and hp.n_envs * hp.algo_kwargs["n_steps"] >= 2048



def test_the_timed_recipes_resolve_with_a_fixed_step_budget() -> None:
    """benchmarks/archive/fast_recipes*.yml are the 10-seed timed sweeps: a fixed number of
    steps (so a seed gives one model), hyperparameters that resolve on their id."""
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.benchmark.grid import load_recipes

    timed = (("fast_recipes.yml", "SGCRod-v1"), ("fast_recipes_point.yml", "SGCPoint-v1"))
    for name, env_id in timed:
        recipes = load_recipes(ROOT / "benchmarks" / "archive" / name)
        assert [r.envs for r in recipes] == [(env_id,)]
        for recipe in recipes:
            assert isinstance(recipe.timesteps, int) and recipe.timesteps > 0
            hp = load_hyperparams(recipe.algo, env_id, recipe.hyperparams)
            assert hp.n_envs == 64 and hp.algo_kwargs["batch_size"] == 1024

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


def test_the_raw_observation_rows_copy_their_ppo_rows_but_the_features() -> None:
    """ppo_raw repeats each env's PPO row (the ablation's point); this keeps the copies aligned."""
    import yaml

    hp = ROOT / "benchmarks" / "hyperparams"
    raw = yaml.safe_load((hp / "ppo_raw" / "ppo.yml").read_text())
    for env_id, folder in (("SGCRod-v1", "ppo_rod300"), ("SGCPoint-v1", "ppo_rod_alive64")):
        ppo = yaml.safe_load((hp / folder / "ppo.yml").read_text())[env_id]
        copy = raw[env_id]
        skip = {"n_timesteps", "policy_kwargs"}  # a budget cap; the features extractor
        assert {k: v for k, v in copy.items() if k not in skip} == {
            k: v for k, v in ppo.items() if k not in skip
        }, env_id
        assert "ScheduleFeatures" in ppo["policy_kwargs"]
        assert copy["policy_kwargs"] == "dict(net_arch=[64, 64], log_std_init=-3.0)"
        assert ppo["policy_kwargs"].startswith("dict(net_arch=[64, 64], log_std_init=-3.0, ")
