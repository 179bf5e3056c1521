"""One benchmark run, wherever it executes: train, score best and final model, pack the files.

:func:`execute_run` takes a plain dict (a :class:`~baselines.benchmark.grid.RunSpec`) and
returns a plain dict, so that a process pool or a Ray worker on another machine can run it:
the run trains into a private temporary folder and the files it wrote come back as bytes
(``files``), for the driver to write under the run folder (:func:`write_outcome`). A failure
comes back as ``status: failed`` with its traceback instead of an exception.
"""

from __future__ import annotations

import json
import shlex
import tempfile
import time
import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Any

from baselines.benchmark.grid import RunSpec, train_command
from baselines.common.atomic_files import write_atomic

if TYPE_CHECKING:
    from baselines.agents.hyperparams import Hyperparams

__all__ = ["FAILED_FILE", "RESULT_FILE", "execute_run", "write_outcome"]

RESULT_FILE = "result.json"
"""Written last: a run folder with it is finished (the grid skips it on resume)."""
FAILED_FILE = "failed.json"
_SKIP = ("checkpoints",)


def _resolved_eval_freq(spec: RunSpec, hp: Hyperparams) -> int:
    """``eval_freq`` 0 means four learning-curve points over the steps the run will take."""
    if spec.eval_freq:
        return spec.eval_freq
    from baselines.agents.budget import whole_rollouts

    total = hp.n_timesteps if spec.recipe.timesteps is None else spec.recipe.timesteps
    return max(whole_rollouts(total, spec.recipe.algo, hp) // CURVE_POINTS, 1)


CURVE_POINTS = 4
"""Learning-curve points per run when ``--eval-freq`` is 0: over its steps, or its budget."""


def _curve_schedule(spec: RunSpec, hp: Hyperparams) -> dict[str, Any]:
    """``eval_freq`` (steps) or, for a run with a time budget and ``--eval-freq 0``,
    ``eval_every_s``: the same four points over the budget for every family."""
    budget = spec.recipe.time_budget_s
    if spec.eval_freq or budget is None:
        return {"eval_freq": _resolved_eval_freq(spec, hp)}
    return {"eval_freq": 0, "eval_every_s": budget / CURVE_POINTS}


def _score(model: Path, spec: RunSpec) -> dict[str, Any]:
    from baselines.evaluation.harness import evaluate, json_ready

    result = evaluate(
        str(model), spec.env_id, spec.eval_episodes, spec.test_seed,
        env_kwargs=dict(spec.recipe.env_kwargs) or None, keep_infos=0,
    )  # fmt: skip
    return json_ready(result.summary)


def _pack(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.relative_to(folder).parts[0] not in _SKIP
    }


def execute_run(spec_dict: dict[str, Any]) -> dict[str, Any]:
    """Train and score one run; never raises (a failure is returned with its traceback)."""
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.agents.train import TrainConfig, train

    spec = RunSpec.from_dict(spec_dict)
    started = time.perf_counter()
    outcome: dict[str, Any] = {"run_id": spec.run_id, "spec": spec_dict}
    try:
        with tempfile.TemporaryDirectory(prefix="sgc-bench-") as tmp:
            out = Path(tmp)
            hp = load_hyperparams(spec.recipe.algo, spec.env_id, spec.recipe.hyperparams)
            options = spec.train_options(out="RUN_DIR")
            options.update(_curve_schedule(spec, hp))
            command = train_command(options)
            options["out"] = str(out)
            result = train(TrainConfig(**options, command=command), hp)
            best = out / "best_model.zip"
            final = Path(result.model_path or out / "final_model.zip")
            scores = {"final": _score(final, spec)}
            scores["best"] = _score(best, spec) if best.is_file() else scores["final"]
            outcome.update(
                status="finished", command=command, timesteps=result.timesteps,
                train_wall_time_s=result.wall_time_s, steps_per_s=result.steps_per_s,
                train_time_s=result.config["train_time_s"],
                train_cpu_s=result.config["train_cpu_s"],
                time_budget_s=spec.recipe.time_budget_s,
                budget_spent=result.config["budget_spent"],
                curve=result.evaluations, scores=scores,
                wall_time_s=time.perf_counter() - started, files=_pack(out),
            )  # fmt: skip
    except Exception as exc:  # noqa: BLE001 - a failed run is recorded, the grid goes on
        outcome.update(
            status="failed", error=f"{type(exc).__name__}: {exc}",
            traceback=traceback.format_exc(), wall_time_s=time.perf_counter() - started,
        )  # fmt: skip
    return outcome


def write_outcome(outcome: dict[str, Any], folder: str | Path) -> Path:
    """Write a run's files and then ``result.json`` (or ``failed.json``) under ``folder``,
    each atomically: a reader or a killed driver never leaves half a file."""
    root = Path(folder)
    root.mkdir(parents=True, exist_ok=True)
    for rel, data in (outcome.get("files") or {}).items():
        write_atomic(root / rel, data)
    record = {k: v for k, v in outcome.items() if k != "files"}
    if outcome.get("status") == "finished":
        (root / FAILED_FILE).unlink(missing_ok=True)
        record["command"] = record["command"].replace("RUN_DIR", shlex.quote(str(root)))
        write_atomic(root / "command.txt", record["command"] + "\n")
        target = root / RESULT_FILE
    else:
        target = root / FAILED_FILE
    return write_atomic(target, json.dumps(record, indent=1, allow_nan=False) + "\n")
