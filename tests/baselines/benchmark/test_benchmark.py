"""`sgc benchmark`: IQM and stratified bootstrap, grid checks, both backends, resume."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from baselines.benchmark.aggregate import (  # noqa: E402
    iqm,
    learning_curve,
    performance_profile,
    stratified_bootstrap_ci,
    summarize_metric,
)
from baselines.benchmark.grid import (  # noqa: E402
    Recipe,
    build_grid,
    load_recipes,
    recipes_from_algos,
    train_command,
)
from baselines.cli import main as cli  # noqa: E402

TINY_PPO = """
SGCPoint-v1:
  n_timesteps: 128
  policy: MlpPolicy
  n_envs: 2
  n_steps: 64
  batch_size: 64
  n_epochs: 2
  policy_kwargs: "dict(net_arch=[16])"
"""


@pytest.fixture()
def tiny_hp(tmp_path: Path) -> Path:
    folder = tmp_path / "hp"
    folder.mkdir()
    (folder / "ppo.yml").write_text(TINY_PPO)
    return folder


# ---------------------------------------------------------------- statistics


def test_iqm_is_the_mean_of_the_middle_half() -> None:
    assert iqm(np.arange(1.0, 9.0)) == pytest.approx(4.5)  # mean of 3, 4, 5, 6
    assert iqm([0.0, 0.0, 0.0, 100.0]) == pytest.approx(0.0)  # outlier trimmed
    assert iqm([0.2, 0.4, 0.9]) == pytest.approx(0.5)  # three runs: nothing to trim


def test_bootstrap_ci_degenerate_cases() -> None:
    assert stratified_bootstrap_ci([[0.3, 0.3, 0.3]]) == pytest.approx((0.3, 0.3))
    assert stratified_bootstrap_ci([[0.7]]) == pytest.approx((0.7, 0.7))
    low, high = stratified_bootstrap_ci([[0.0, 1.0]], np.mean)
    assert low == 0.0 and high == 1.0  # resamples {0,0}, {0,1}, {1,1}: all three occur


def test_bootstrap_is_stratified_by_task() -> None:
    # Each task is constant, so resampling within tasks always pools three 0s and three 1s;
    # resampling across tasks would not, and its interval would be wide.
    strata = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
    assert stratified_bootstrap_ci(strata, np.mean) == pytest.approx((0.5, 0.5))
    assert stratified_bootstrap_ci([[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]], np.mean) != (0.5, 0.5)


def test_bootstrap_matches_scipy_for_one_stratum() -> None:
    from scipy.stats import bootstrap

    x = np.random.default_rng(1).normal(size=40)
    ours = stratified_bootstrap_ci([x], np.mean, n_resamples=20_000)
    ref = bootstrap((x,), np.mean, method="percentile", n_resamples=20_000, random_state=2)
    assert ours == pytest.approx(tuple(ref.confidence_interval), abs=0.03)


def test_bootstrap_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="non-empty"):
        stratified_bootstrap_ci([[]])
    with pytest.raises(ValueError, match="finite"):
        stratified_bootstrap_ci([[1.0, np.nan]])


def test_summarize_metric_skips_missing_values() -> None:
    stats = summarize_metric([[0.25, None, 0.75, float("nan")]])
    assert stats["n"] == 2 and stats["mean"] == pytest.approx(0.5)
    assert summarize_metric([[None]])["iqm"] is None


def test_performance_profile_counts_runs_above_tau() -> None:
    prof = performance_profile([[0.2, 0.6, 1.0]], [0.0, 0.5, 1.0])
    assert prof["fraction"] == pytest.approx([1.0, 2 / 3, 0.0])
    bands = zip(prof["low"], prof["fraction"], prof["high"], strict=True)
    assert all(lo <= f <= hi for lo, f, hi in bands)


def test_learning_curve_uses_steps_every_run_has() -> None:
    runs = [
        {"curve": [{"timesteps": 10, "success_rate": 0.0}, {"timesteps": 20, "success_rate": 1.0}]},
        {"curve": [{"timesteps": 10, "success_rate": 0.5}]},
    ]
    curve = learning_curve(runs)
    assert curve["timesteps"] == [10] and curve["iqm"] == pytest.approx([0.25])


# ---------------------------------------------------------------- grid


def test_train_command_reproduces_the_options(tiny_hp: Path) -> None:
    recipes = recipes_from_algos(["ppo"], str(tiny_hp), {"observation": "planner"}, 64)
    (spec,) = build_grid(recipes, ["SGCPoint-v1"], [3], eval_freq=64, curve_episodes=1,
                         eval_episodes=2)  # fmt: skip
    command = train_command(spec.train_options(out="DIR"))
    assert command == (f"sgc train --algo ppo --env SGCPoint-v1 --seed 3 --timesteps 64 "
                       f"--out DIR --eval-freq 64 --eval-episodes 1 --hyperparams {tiny_hp} "
                       "--env-kwargs '{\"observation\": \"planner\"}'")  # fmt: skip


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"env_ids": ["Nope-v0"]}, "--env: unknown environment"),
        ({"seeds": [0, 0]}, "distinct seeds"),
        ({"seeds": []}, "distinct seeds"),
        ({"eval_episodes": 0}, "--eval-episodes"),
        ({"test_seed": 10_001}, "overlap"),
        ({"recipes": [Recipe("a", "ppo"), Recipe("a", "sac")]}, "more than once"),
        ({"recipes": []}, "give --algo or --recipes"),
        ({"recipes": [Recipe("a", "ppo", env_kwargs={"a": 1})]}, "does not take {'a': 1}"),
    ],
)
def test_bad_grid_arguments_are_named(kwargs: dict, message: str) -> None:
    args = {"recipes": [Recipe("ppo", "ppo")], "env_ids": ["SGCPoint-v1"], "seeds": [0],
            "eval_freq": 0, "curve_episodes": 1, "eval_episodes": 2, **kwargs}  # fmt: skip
    with pytest.raises(ValueError, match=message):
        build_grid(args.pop("recipes"), args.pop("env_ids"), args.pop("seeds"), **args)


def test_recipes_file(tmp_path: Path, tiny_hp: Path) -> None:
    path = tmp_path / "recipes.yml"
    path.write_text(
        "recipes:\n  - {name: tiny, algo: ppo, hyperparams: hp, timesteps: 64}\n"
        "  - {name: clone, algo: ppo, train: {init: bc, demos: 'd/{env_id}.npz', "
        "dagger_rounds: 2}}\n"
    )
    tiny, clone = load_recipes(path)
    assert tiny.hyperparams == str(tiny_hp) and not tiny.demonstrations
    assert clone.demonstrations
    (spec,) = build_grid([clone], ["SGCPoint-v1"], [0], eval_freq=0, curve_episodes=1,
                         eval_episodes=1)  # fmt: skip
    assert spec.train_options(None)["demos"] == "d/SGCPoint-v1.npz"
    path.write_text("recipes:\n  - {algo: ppo, train: {seed: 3}}\n")
    with pytest.raises(ValueError, match=r"recipe 0: train option\(s\) \['seed'\]"):
        load_recipes(path)
    path.write_text("recipes:\n  - {algo: dqn}\n")
    with pytest.raises(ValueError, match="algo must be one of"):
        load_recipes(path)


def test_a_recipe_runs_only_on_its_envs(tmp_path: Path) -> None:
    (tmp_path / "hp").mkdir()
    (tmp_path / "hp" / "ppo.yml").write_text(
        "SGCPoint-v1: &p {n_timesteps: 64, policy: MlpPolicy}\nSGCPointGoal-v1: *p\n"
    )
    path = tmp_path / "recipes.yml"
    path.write_text(
        "recipes:\n  - {name: everywhere, algo: ppo, hyperparams: hp}\n"
        "  - {name: goal-only, algo: her, envs: [SGCPointGoal-v1]}\n"
    )
    everywhere, goal_only = load_recipes(path)
    assert goal_only.envs == ("SGCPointGoal-v1",) and everywhere.envs == ()
    grid = build_grid([everywhere, goal_only], ["SGCPoint-v1", "SGCPointGoal-v1"], [0, 1],
                      eval_freq=0, curve_episodes=1, eval_episodes=1)  # fmt: skip
    cells = [(spec.env_id, spec.recipe.name) for spec in grid]
    assert ("SGCPoint-v1", "goal-only") not in cells
    assert cells.count(("SGCPointGoal-v1", "goal-only")) == 2 and len(cells) == 6
    with pytest.raises(ValueError, match="none of its envs"):
        build_grid([goal_only], ["SGCPoint-v1"], [0], eval_freq=0, curve_episodes=1,
                   eval_episodes=1)  # fmt: skip
    path.write_text("recipes:\n  - {algo: ppo, envs: [Nope-v0]}\n")
    with pytest.raises(ValueError, match="recipe 0: envs"):
        load_recipes(path)
    path.write_text("recipes:\n  - {algo: ppo, envs: SGCPoint-v1}\n")
    with pytest.raises(ValueError, match="envs must be a list"):
        load_recipes(path)


def test_cli_reports_bad_arguments(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    argv = ["benchmark", "--algo", "ppo", "--env", "SGCPoint-v1", "--seeds", "0",
            "--out", str(tmp_path)]  # fmt: skip
    assert cli.main(argv) == 2
    assert "--seeds must be >= 1" in capsys.readouterr().err
    assert cli.main([*argv[:5], "--backend", "local", "--address", "x"]) == 2
    assert "--address is for --backend ray" in capsys.readouterr().err


def test_a_lost_worker_is_a_failed_run_and_the_grid_goes_on() -> None:
    from baselines.benchmark.backends import _throttled

    def collect(handle: dict) -> dict:
        if handle["run_id"] == "b":
            raise RuntimeError("worker died")
        return {"run_id": handle["run_id"], "status": "finished"}

    started: list[str] = []
    specs = [{"run_id": name} for name in "abc"]
    outcomes = list(_throttled(specs, 2, dict, lambda p: (p[:1], p[1:]), collect, started.append))
    assert started == ["a", "b", "c"]
    assert [(o["run_id"], o["status"]) for o in outcomes] == [
        ("a", "finished"),
        ("b", "failed"),
        ("c", "finished"),
    ]
    assert "worker died" in outcomes[1]["error"]


# ---------------------------------------------------------------- end to end


def _tiny_argv(out: Path, hp: Path, *extra: str) -> list[str]:
    return ["benchmark", "--algo", "ppo", "--env", "SGCPoint-v1", "--seeds", "2",
            "--timesteps", "128", "--eval-episodes", "2", "--curve-episodes", "1",
            "--eval-freq", "128", "--hyperparams", str(hp), "--workers", "2", "--no-plots",
            "--out", str(out), *extra]  # fmt: skip


_RUN_DEPENDENT = ("wall_time_s", "steps_per_s", "commands", "train_time_s", "train_cpu_s")


def _rows(out: Path) -> list[dict]:
    rows = json.loads((out / "leaderboard.json").read_text())["rows"]
    return [{k: v for k, v in row.items() if k not in _RUN_DEPENDENT} for row in rows]


def test_local_and_ray_give_the_same_leaderboard_and_resume(tmp_path: Path, tiny_hp: Path) -> None:
    pytest.importorskip("ray")
    local, ray_out = tmp_path / "local", tmp_path / "ray"
    assert cli.main(_tiny_argv(local, tiny_hp)) == 0
    assert cli.main(_tiny_argv(ray_out, tiny_hp, "--backend", "ray")) == 0
    rows = _rows(local)
    assert rows == _rows(ray_out)
    (row,) = rows
    assert row["seeds"] == [0, 1] and row["timesteps"] == [128, 128]
    assert row["final"]["success_rate"]["n"] == 2
    run = local / "runs" / "SGCPoint-v1" / "ppo" / "seed1"
    for name in ("config.json", "command.txt", "final_model.zip", "best_model.zip"):
        assert (run / name).is_file(), name
    command = (run / "command.txt").read_text()
    assert "--seed 1" in command and f"--out {run}" in command
    stamp = (run / "result.json").stat().st_mtime_ns
    assert cli.main(_tiny_argv(local, tiny_hp)) == 0  # resumed: nothing left to run
    assert (run / "result.json").stat().st_mtime_ns == stamp
    assert _rows(local) == rows


def test_failed_runs_are_recorded_and_retried_on_request(
    tmp_path: Path, tiny_hp: Path, capsys: pytest.CaptureFixture
) -> None:
    recipes = tmp_path / "r.yml"
    recipes.write_text(f"recipes:\n  - {{name: clone, algo: ppo, hyperparams: {tiny_hp}, "
                       "timesteps: 0, train: {init: bc, demos: missing.npz}}\n")  # fmt: skip
    argv = ["benchmark", "--recipes", str(recipes), "--env", "SGCPoint-v1", "--seeds", "1",
            "--eval-episodes", "1", "--curve-episodes", "1", "--workers", "1", "--no-plots",
            "--out", str(tmp_path / "b")]  # fmt: skip
    assert cli.main(argv) == 1
    failed = tmp_path / "b" / "runs" / "SGCPoint-v1" / "clone" / "seed0" / "failed.json"
    record = json.loads(failed.read_text())
    assert record["status"] == "failed" and "missing.npz" in record["traceback"]
    assert "1 failed before (skipped" not in capsys.readouterr().out
    assert cli.main(argv) == 1
    assert "0 to run" in capsys.readouterr().out
    assert cli.main([*argv, "--retry-failed"]) == 1
    assert "1 to run" in capsys.readouterr().out
    board = json.loads((tmp_path / "b" / "leaderboard.json").read_text())
    assert board["rows"][0]["failed_seeds"] == [0] and board["rows"][0]["seeds"] == []


# ---------------------------------------------------------------- killed and concurrent drivers
# Real processes on the tiny grid (one worker), so that SIGKILL and two drivers racing for one
# folder are what happens, not a simulation of it.

ROOT = Path(__file__).resolve().parents[3]


def _process_argv(out: Path, hp: Path) -> list[str]:
    """The tiny grid with one worker, as its own process."""
    return [sys.executable, "-m", "baselines.cli.main", *_tiny_argv(out, hp, "--workers", "1")]


def _start(out: Path, hp: Path) -> subprocess.Popen:
    path = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    return subprocess.Popen(_process_argv(out, hp), env={**os.environ, "PYTHONPATH": path},
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)  # fmt: skip


def _run(out: Path, seed: int) -> Path:
    return out / "runs" / "SGCPoint-v1" / "ppo" / f"seed{seed}"


def test_sigkill_mid_grid_resumes_without_retraining_the_finished_run(
    tmp_path: Path, tiny_hp: Path, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "bench"
    first = _run(out, 0) / "result.json"
    proc = _start(out, tiny_hp)
    deadline = time.monotonic() + 240
    while not first.is_file() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)  # the driver and anything it started
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stdout.read() if proc.stdout else ""
    assert first.is_file() and not (_run(out, 1) / "result.json").exists()
    before = (first.read_bytes(), first.stat().st_mtime_ns)
    json.loads(before[0])  # whole, not half written
    assert cli.main(_process_argv(out, tiny_hp)[3:]) == 0  # the same command, in this process
    again = capsys.readouterr().out
    assert "2 runs: 1 finished before" in again and "1 to run" in again
    assert "seed0: finished" not in again and "seed1: finished" in again
    assert (first.read_bytes(), first.stat().st_mtime_ns) == before  # not retrained
    rows = json.loads((out / "leaderboard.json").read_text())["rows"]
    assert rows[0]["seeds"] == [0, 1]


def test_two_benchmarks_on_one_out_train_each_run_once_and_leave_it_whole(
    tmp_path: Path, tiny_hp: Path
) -> None:
    out = tmp_path / "bench"
    procs = [_start(out, tiny_hp), _start(out, tiny_hp)]
    logs = [p.communicate(timeout=300)[0] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], logs
    trained = [line for log in logs for line in log.splitlines() if ": finished in" in line]
    assert sorted(line.split(":")[0] for line in trained) == [
        "SGCPoint-v1/ppo/seed0", "SGCPoint-v1/ppo/seed1",
    ], logs  # fmt: skip
    for seed in (0, 1):
        record = json.loads((_run(out, seed) / "result.json").read_text())
        assert record["status"] == "finished" and record["spec"]["seed"] == seed
    assert not list(out.rglob("*.tmp")), "a temporary file was left behind"
    board = json.loads((out / "leaderboard.json").read_text())  # the last to finish wrote it
    assert board["rows"][0]["seeds"] == [0, 1] and board["meta"]["finished"] == 2
