"""Per-seed table and aggregate of rl-zoo3 runs: held-out goals met, steps, training seconds.

rl-zoo3's trainer (``python -m rl_zoo3.train ... -f logs``) leaves one folder per run,
``logs/<algo>/<env>_<n>/``, with the model ``<env>.zip``, the ``Monitor`` files of its
sub-envs and, with ``normalize``, ``<env>/vecnormalize.pkl`` (convert it once with
``sgc convert --trust-model``: the harness never unpickles). For every run this scores the
model with the harness on held-out reset seeds (``--seed`` .. ``--seed + --episodes - 1``,
none of which training sees) and prints a row; then the interquartile mean of the success
rates with a 95 % stratified-bootstrap CI (:mod:`baselines.benchmark.aggregate`) and how many
runs meet 80 % of the goals::

    python scripts/zoo_seed_table.py logs/ppo/SGCRod-v1_* [--episodes 50] [--seed 20000] \
        [--json rod_seeds.json]

Read from the run, nothing unpickled: the training seed and steps from the model's ``data``
JSON, the training seconds from the ``Monitor`` files (the last episode's end, ``t``, on
the first sub-env's clock: an upper bound that leaves out rl-zoo3's start-up).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from baselines.benchmark.aggregate import iqm, stratified_bootstrap_ci
from baselines.models.model_files import read_model_data
from baselines.zoo.manifest import held_out_result
from sgc_env.scenario.bounded import escaped, load_json, read_text

GOAL_RATE = 0.8


def _model(run: Path) -> Path:
    """The run's ``<env>.zip`` (rl-zoo3 names the final model after the env id)."""
    models = sorted(run.glob("*.zip"))
    if len(models) != 1:
        raise ValueError(f"{run}: expected one final model <env>.zip, found {len(models)}")
    return models[0]


def _monitor_span(path: Path) -> tuple[float, float | None]:
    """(start, end of the last finished episode or None) of one Monitor file, read through the
    project's bounded reader: a run folder may come from elsewhere."""
    what = "Monitor file"
    lines = read_text(path, what).splitlines()
    where = f"{what} {escaped(path)}"
    if not lines or not lines[0].startswith("#"):
        raise ValueError(f"{where}: no '#{{...}}' header line (not a Monitor file)")
    header = load_json(lines[0][1:], f"{where}: header")
    rows = list(csv.DictReader(lines[1:]))
    try:
        start = float(header["t_start"])
        end = start + float(rows[-1]["t"]) if rows else None
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(
            f"{where}: no t_start in the header or no t column ({escaped(exc)})"
        ) from None
    if not math.isfinite(start) or (end is not None and not math.isfinite(end)):
        raise ValueError(f"{where}: t_start and t must be finite numbers")
    return start, end


def training_seconds(run: Path) -> float:
    """The end of the last finished episode over the run's Monitor files (seconds since the
    first Monitor file's start)."""
    files = sorted(run.glob("*.monitor.csv"))
    if not files:
        raise ValueError(f"{run}: no *.monitor.csv files (not an rl-zoo3 run folder)")
    spans = [_monitor_span(path) for path in files]
    ends = [end for _, end in spans if end is not None]
    if not ends:
        raise ValueError(f"{run}: no finished episode in the Monitor files")
    return max(ends) - min(start for start, _ in spans)


def seed_row(run: Path, episodes: int, seed: int) -> dict[str, Any]:
    """One run's figures; ``ValueError`` naming the folder when it is not a finished run."""
    model = _model(run)
    data, _ = read_model_data(model.read_bytes(), str(model))
    env_id = model.stem
    result = held_out_result(model, env_id, episodes, seed)
    return {
        "run": str(run), "env_id": env_id, "seed": data.get("seed"),
        "steps": int(data["num_timesteps"]), "training_s": round(training_seconds(run), 1),
        "goals_met": result["goals_met"], "n_goals": result["n_goals"],
        "success_rate": result["success_rate"], "result": result,
    }  # fmt: skip


def summary(rows: list[dict[str, Any]]) -> str:
    """IQM of the success rates with its CI (runs of one env are one stratum per env)."""
    by_env: dict[str, list[float]] = {}
    for r in rows:
        by_env.setdefault(r["env_id"], []).append(float(r["success_rate"]))
    rates = [rate for env in by_env.values() for rate in env]
    low, high = stratified_bootstrap_ci(list(by_env.values()), iqm)
    met = sum(rate >= GOAL_RATE for rate in rates)
    centre = iqm(np.asarray(rates))
    return (f"IQM {centre:.3f} [95 % CI {low:.3f}, {high:.3f}]; {met}/{len(rates)} runs "
            f"meet >= {GOAL_RATE:.0%} of held-out goals")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="rl-zoo3 run folders")
    parser.add_argument("--episodes", type=int, default=50, help="held-out episodes per run")
    parser.add_argument("--seed", type=int, default=20_000, help="first held-out reset seed")
    parser.add_argument("--json", type=Path, help="also write the rows here")
    args = parser.parse_args()
    rows = sorted(
        (seed_row(run, args.episodes, args.seed) for run in args.runs),
        key=lambda r: (r["env_id"], r["seed"] if r["seed"] is not None else -1),
    )
    print("| env | seed | steps | training (s) | goals met | rate | position error mean / max (m) |"
          "\n|---|---|---|---|---|---|---|")  # fmt: skip
    for r in rows:
        res = r["result"]
        print(f"| {r['env_id']} | {r['seed']} | {r['steps']:,} | {r['training_s']:.0f} | "
              f"{r['goals_met']:.0f}/{r['n_goals']:.0f} | {r['success_rate']:.2f} | "
              f"{res['position_error_mean']:.4f} / {res['position_error_max']:.4f} |")  # fmt: skip
    print(f"\n{summary(rows)}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
