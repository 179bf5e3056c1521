"""Wall-clock budgets (issue 21): the callback stops learn(), runs record what they reached,
the leaderboard shows budget, steps reached and curves against steps and wall clock."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
import yaml

pytest.importorskip("stable_baselines3")

from baselines.agents.budget import TimeBudgetCallback, check_time_budget  # noqa: E402
from baselines.benchmark.aggregate import aggregate_runs, learning_curve  # noqa: E402
from baselines.benchmark.grid import (  # noqa: E402
    build_grid,
    load_recipes,
    recipes_from_algos,
    train_command,
)
from baselines.benchmark.report import markdown, write_report  # noqa: E402
from baselines.cli import main as cli  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
#: PPO small enough that one update takes milliseconds (the budget's overshoot is one update).
TINY_PPO = {"n_timesteps": 128, "policy": "MlpPolicy", "n_envs": 2, "n_steps": 32,
            "batch_size": 64, "n_epochs": 1, "policy_kwargs": "dict(net_arch=[8])"}  # fmt: skip


@pytest.fixture()
def tiny_hp(tmp_path: Path) -> Path:
    (tmp_path / "ppo.yml").write_text(yaml.safe_dump({"SGCPoint-v1": TINY_PPO}))
    return tmp_path


@pytest.mark.parametrize("bad", [0, -1.0, math.inf, math.nan, "300", True])
def test_a_budget_is_a_finite_positive_number_of_seconds(bad: Any) -> None:
    with pytest.raises(ValueError, match="time_budget_s"):
        check_time_budget(bad)
    with pytest.raises(ValueError, match="budget_s"):
        TimeBudgetCallback(bad)
    assert check_time_budget(None) is None and check_time_budget(300) == 300.0


def test_train_refuses_a_bad_budget_and_two_curve_schedules() -> None:
    from baselines.agents.train import TrainConfig, train

    with pytest.raises(ValueError, match="time_budget_s"):
        train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", time_budget_s=-1.0))
    with pytest.raises(ValueError, match="not both"):
        train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", eval_freq=10, eval_every_s=1.0))


def test_the_budget_stops_a_short_learn(tmp_path: Path, tiny_hp: Path) -> None:
    from baselines.agents.train import TrainConfig, train

    result = train(TrainConfig(
        algo="ppo", env_id="SGCPoint-v1", timesteps=10_000_000, hyperparams_dir=tiny_hp,
        time_budget_s=1.0, eval_every_s=0.6, eval_episodes=1, out=tmp_path / "run",
    ))  # fmt: skip
    config = json.loads((tmp_path / "run" / "config.json").read_text())
    assert config["budget_spent"] is True and config["time_budget_s"] == 1.0
    assert 0 < config["steps_reached"] == result.timesteps < 10_000_000
    # stopped at the budget: one env step plus one PPO update of 64 samples past it at most
    assert 1.0 <= config["train_time_s"] < 5.0 and config["train_cpu_s"] > 0
    # curve points every 0.5 s of training, each with its steps and seconds
    times = [e["train_time_s"] for e in result.evaluations]
    assert len(times) >= 2 and times == sorted(times) and times[0] >= 0.6
    assert [e["timesteps"] for e in result.evaluations][-1] == result.timesteps


def test_without_a_budget_the_steps_bound_the_run(tiny_hp: Path) -> None:
    from baselines.agents.train import TrainConfig, train

    result = train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", timesteps=64,
                               hyperparams_dir=tiny_hp, time_budget_s=600.0))  # fmt: skip
    assert result.timesteps == 64 and result.config["budget_spent"] is False


def test_sgc_train_refuses_a_bad_budget(capsys: pytest.CaptureFixture[str]) -> None:
    for bad in ("0", "-5", "inf", "nan", "soon"):
        assert cli.main(["train", "--algo", "ppo", "--env", "SGCPoint-v1",
                         "--time-budget", bad]) == 2  # fmt: skip
        assert "--time-budget" in capsys.readouterr().err


def test_recipe_budget_reaches_the_train_command(tmp_path: Path, tiny_hp: Path) -> None:
    (recipe,) = recipes_from_algos(["ppo"], str(tiny_hp), time_budget_s=120)
    (spec,) = build_grid([recipe], ["SGCPoint-v1"], [0], eval_freq=0, curve_episodes=1,
                         eval_episodes=2)  # fmt: skip
    assert "--time-budget 120" in train_command(spec.train_options(out="DIR"))
    bad = tmp_path / "recipes.yml"
    bad.write_text(f"recipes:\n  - {{name: x, algo: ppo, hyperparams: {tiny_hp}, "
                   "time_budget_s: 0}\n")  # fmt: skip
    with pytest.raises(ValueError, match="recipe 0: time_budget_s"):
        load_recipes(bad)


def test_budget_recipes_share_one_budget_per_env() -> None:
    """Every issue-21 budget row of an env gets the same seconds (the equal wall clock)."""
    recipes = [r for r in load_recipes(ROOT / "benchmarks" / "recipes.yml") if r.time_budget_s]
    budgets: dict[str, set[float]] = {}
    for recipe in recipes:
        for env_id in recipe.envs:
            base = env_id.replace("Goal", "")  # the time-carrying point counts as the point
            budgets.setdefault(base, set()).add(recipe.time_budget_s)  # type: ignore[arg-type]
    assert set(budgets) >= {"SGCPoint-v1", "SGCRod-v1"}
    assert all(len(b) == 1 for b in budgets.values()), budgets
    assert {r.algo for r in recipes} >= {"ppo", "sac", "td3", "her"}


# ---------------------------------------------------------------- leaderboard on fake runs


def _fake_run(seed: int, steps: int, curve: list[tuple[int, float, float]]) -> dict[str, Any]:
    (recipe,) = recipes_from_algos(["sac"], time_budget_s=300)
    (spec,) = build_grid([recipe], ["SGCRod-v1"], [seed], eval_freq=0, curve_episodes=1,
                         eval_episodes=2)  # fmt: skip
    score = {"success_rate": curve[-1][2]}
    return {
        "spec": spec.to_dict(), "timesteps": steps, "train_time_s": 300.0 + seed,
        "train_cpu_s": 270.0 + seed,
        "wall_time_s": 320.0 + seed, "steps_per_s": steps / 300, "command": "sgc train",
        "time_budget_s": 300, "scores": {"final": score, "best": score},
        "curve": [{"timesteps": n, "train_time_s": t, "success_rate": s} for n, t, s in curve],
    }  # fmt: skip


FAKE = [
    _fake_run(0, 9000, [(3000, 75.0, 0.0), (6000, 150.0, 0.5), (9000, 300.0, 1.0)]),
    _fake_run(1, 6000, [(2000, 76.0, 0.0), (4000, 151.0, 0.0), (6000, 301.0, 0.5)]),
    _fake_run(2, 7000, [(2500, 77.0, 0.5), (5000, 152.0, 0.5), (7000, 302.0, 0.5)]),
]


def test_curves_align_the_kth_point_of_every_seed() -> None:
    steps = learning_curve(FAKE)
    clock = learning_curve(FAKE, axis="train_time_s")
    assert steps["timesteps"] == [2500, 5000, 7000]  # medians: under a budget steps vary
    assert steps["timesteps_range"][-1] == [6000, 9000]
    assert clock["train_time_s"] == [76.0, 151.0, 301.0]
    assert clock["iqm"] == steps["iqm"] and steps["iqm"][-1] == pytest.approx(2 / 3)
    old = [{"curve": [{"timesteps": 10, "success_rate": 0.0}]}]  # a run from before budgets
    assert learning_curve(old, axis="train_time_s")["iqm"] == []
    with pytest.raises(ValueError, match="axis"):
        learning_curve(FAKE, axis="episodes")


def test_leaderboard_shows_budget_steps_reached_and_both_curves(tmp_path: Path) -> None:
    rows = aggregate_runs(FAKE)
    (row,) = rows
    assert row["time_budget_s"] == 300 and row["timesteps"] == [9000, 6000, 7000]
    meta = {"command": "sgc benchmark", "eval_episodes": 2, "test_seed": 20000,
            "eval_seed": 10000}  # fmt: skip
    text = markdown(rows, meta)
    assert "budget / run (s)" in text and "steps reached: median [range]" in text
    assert "| 300 | 7,000 [6,000, 9,000] | 301 [300, 302] | 0.90 |" in text
    written = write_report(rows, FAKE, meta, tmp_path)
    assert (tmp_path / "SGCRod-v1.png") in written
    data = json.loads((tmp_path / "leaderboard.json").read_text())
    curve = data["learning_curves"]["SGCRod-v1/sac"]
    assert curve["timesteps"] == [2500, 5000, 7000]
    assert curve["wall_clock"]["train_time_s"] == [76.0, 151.0, 301.0]


def test_the_sweep_script_runs_every_budget_recipe() -> None:
    text = (ROOT / "scripts" / "run_budget_rows.sh").read_text()
    rows = {name for line in text.splitlines() if line.startswith("ALL=")
            for name in line.split("=", 1)[1].replace("$ALL,", "").split(",")}  # fmt: skip
    recipes = load_recipes(ROOT / "benchmarks" / "recipes.yml")
    assert rows == {r.name for r in recipes if r.time_budget_s is not None}


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_a_budget_run_is_the_fixed_step_run_cut_where_the_budget_ended(
    tiny_hp: Path, algo: str
) -> None:
    """The docs' determinism claim: the seed fixes the run up to the steps it learned from."""
    import torch as th

    from baselines.agents.train import TrainConfig, train

    (tiny_hp / "sac.yml").write_text(yaml.safe_dump({"SGCPoint-v1": {
        "n_timesteps": 64, "policy": "MlpPolicy", "n_envs": 2, "learning_starts": 20,
        "batch_size": 16, "train_freq": 3, "policy_kwargs": "dict(net_arch=[8])",
    }}))  # fmt: skip
    common = {"algo": algo, "env_id": "SGCPoint-v1", "seed": 4, "hyperparams_dir": tiny_hp}
    cut = train(TrainConfig(**common, timesteps=10_000_000, time_budget_s=0.5))
    learned = cut.config["steps_learned"]
    chunk = 64 if algo == "ppo" else 6  # a rollout of 2 x 32; train_freq 3 x 2 envs
    assert learned % chunk == 0 and cut.timesteps - chunk - 2 < learned < cut.timesteps
    again = train(TrainConfig(**common, timesteps=learned))
    assert again.config["steps_learned"] == learned
    for a, b in zip(cut.model.policy.parameters(), again.model.policy.parameters(), strict=True):
        assert th.equal(a, b)


def test_the_budget_ends_dagger_rounds(tmp_path: Path) -> None:
    from baselines.agents.demos import record_demos
    from baselines.agents.train import TrainConfig, train

    demos = record_demos("SGCPoint-v1", 1, seed=5).save(tmp_path / "demos.npz")
    result = train(TrainConfig(
        algo="ppo", env_id="SGCPoint-v1", timesteps=0, init="bc", demos=demos, bc_epochs=1,
        dagger_rounds=50, dagger_episodes=1, time_budget_s=1.0,
    ))  # fmt: skip
    assert result.config["budget_spent"] is True and result.timesteps == 0
    # 50 rounds would take several seconds: the budget ended them (maybe before the first,
    # where cloning alone took the second on a loaded machine)
    assert len(result.bc["dagger_rounds"]) < 50  # type: ignore[index]
    assert result.config["train_time_s"] >= 1.0


def test_a_benchmark_run_under_a_budget_puts_its_curve_by_seconds(tiny_hp: Path) -> None:
    from baselines.benchmark.execute import execute_run

    (recipe,) = recipes_from_algos(["ppo"], str(tiny_hp), timesteps=10_000_000,
                                   time_budget_s=1.0)  # fmt: skip
    (spec,) = build_grid([recipe], ["SGCPoint-v1"], [0], eval_freq=0, curve_episodes=1,
                         eval_episodes=1)  # fmt: skip
    outcome = execute_run(spec.to_dict())
    assert outcome["status"] == "finished", outcome.get("traceback")
    assert "--time-budget 1.0" in outcome["command"] and "--eval-every-s 0.25" in outcome["command"]
    assert outcome["time_budget_s"] == 1.0 and outcome["budget_spent"] is True
    times = [e["train_time_s"] for e in outcome["curve"]]
    # four points, 0.25 s of training apart (one is skipped if a pause of the machine jumps it)
    assert 2 <= len(times) <= 4 and times[0] >= 0.25 and times[-1] >= 1.0


def test_sgc_benchmark_names_a_bad_budget_or_recipe(
    tmp_path: Path, tiny_hp: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = ["benchmark", "--algo", "ppo", "--hyperparams", str(tiny_hp), "--env", "SGCPoint-v1",
            "--out", str(tmp_path / "out"), "--report-only", "--no-plots"]  # fmt: skip
    assert cli.main([*base, "--time-budget", "0"]) == 2
    assert "time_budget_s" in capsys.readouterr().err
    assert cli.main([*base, "--only", "nope"]) == 2
    assert "--only: no recipe named ['nope']" in capsys.readouterr().err
    assert cli.main([*base, "--only", "ppo", "--time-budget", "5"]) == 0
