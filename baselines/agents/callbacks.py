"""Training callbacks: score the model with the benchmark's own harness while it trains.

SB3's ``EvalCallback`` measures mean return, which for this task says little about what the
benchmark grades (goals met within tolerance, punctuality, smoothness). This callback follows
its pattern (every ``eval_freq`` env steps, held-out seeds, keep the best model) but runs
:func:`baselines.evaluation.harness.evaluate` on the current model instead.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback

from baselines.models.normalization import save_statistics
from baselines.policies import NormalizedPolicy
from sgc_env.defaults import EVAL_SEED

__all__ = [
    "EVAL_SEED",
    "FreezeActorCallback",
    "HarnessEvalCallback",
    "StatisticsCheckpointCallback",
    "score_key",
]


def _scalar_items(summary: dict[str, Any], prefix: str = "") -> dict[str, float]:
    """Flatten numeric entries of the harness scorecard (nested dicts joined with '/')."""
    out: dict[str, float] = {}
    for key, value in summary.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_scalar_items(value, f"{name}/"))
        elif isinstance(value, (bool, int, float, np.integer, np.floating)):
            if math.isfinite(float(value)):
                out[name] = float(value)
    return out


def score_key(summary: dict[str, Any]) -> tuple[float, float]:
    """Best model = highest ``success_rate``, then smallest ``position_error_mean``."""
    success = float(summary.get("success_rate", 0.0) or 0.0)
    error = float(summary.get("position_error_mean", math.inf))
    success = success if math.isfinite(success) else 0.0
    return success, -(error if math.isfinite(error) else math.inf)


class HarnessEvalCallback(BaseCallback):
    """Every ``eval_freq`` env steps (or ``every_s`` seconds of training): score on held-out
    seeds, log, keep the best model.

    Each entry of ``history`` holds ``timesteps`` and ``train_time_s``, the seconds of training
    since ``started`` (a ``time.perf_counter()`` reading; default: the start of ``learn()``)
    less the evaluations themselves, so curves can be drawn against steps and wall clock.
    """

    def __init__(
        self,
        env_id: str,
        eval_freq: int,
        n_eval_episodes: int = 10,
        seed: int = EVAL_SEED,
        env_kwargs: dict[str, Any] | None = None,
        best_model_dir: str | Path | None = None,
        vec_normalize: Any | None = None,
        verbose: int = 0,
        every_s: float | None = None,
        started: float | None = None,
    ) -> None:
        super().__init__(verbose)
        if (eval_freq < 1 and every_s is None) or n_eval_episodes < 1:
            raise ValueError(
                f"eval_freq and eval_episodes must be >= 1, got {eval_freq}, {n_eval_episodes}"
            )
        if every_s is not None and not (math.isfinite(every_s) and every_s > 0):
            raise ValueError(f"every_s must be a finite number of seconds > 0, got {every_s}")
        self.every_s = every_s
        self.started = started
        self.env_id = env_id
        self.eval_freq = int(eval_freq)
        self.n_eval_episodes = int(n_eval_episodes)
        self.seed = int(seed)
        self.env_kwargs = dict(env_kwargs or {})
        self.best_model_dir = Path(best_model_dir) if best_model_dir else None
        self.vec_normalize = vec_normalize
        self.best_score: tuple[float, float] = (-math.inf, -math.inf)
        self.history: list[dict[str, Any]] = []
        self._last_eval = 0
        self._next_eval_s = every_s
        self.eval_time_s = 0.0
        self.eval_cpu_s = 0.0  # this process's CPU seconds in the evaluations

    def train_time_s(self) -> float:
        """Seconds of training so far, the evaluations taken off."""
        if self.started is None:
            return 0.0
        return time.perf_counter() - self.started - self.eval_time_s

    def _on_training_start(self) -> None:
        if self.started is None:
            self.started = time.perf_counter()

    def _policy(self) -> Any:
        if self.vec_normalize is not None:
            return NormalizedPolicy(self.model, self.vec_normalize)
        return self.model

    def evaluate_now(self) -> dict[str, Any]:
        """Run the harness once and record the result (also used after training)."""
        from baselines.evaluation.harness import evaluate

        train_time = self.train_time_s()
        started, cpu_started = time.perf_counter(), time.process_time()
        result = evaluate(
            self._policy(), self.env_id, self.n_eval_episodes, self.seed,
            env_kwargs=self.env_kwargs or None,
        )  # fmt: skip
        self.eval_time_s += time.perf_counter() - started
        self.eval_cpu_s += time.process_time() - cpu_started
        summary = dict(result.summary)
        flat = _scalar_items(summary)
        for key, value in flat.items():
            self.logger.record(f"eval/{key}", value)
        entry = {"timesteps": int(self.num_timesteps), "train_time_s": train_time, **flat}
        self.history.append(entry)
        score = score_key(summary)
        if score > self.best_score:
            self.best_score = score
            if self.best_model_dir is not None:
                self.best_model_dir.mkdir(parents=True, exist_ok=True)
                self.model.save(self.best_model_dir / "best_model")
                if self.vec_normalize is not None:
                    save_statistics(self.vec_normalize, self.best_model_dir / "vecnormalize.json")
        if self.best_model_dir is not None:
            (self.best_model_dir / "evaluations.json").write_text(
                json.dumps(self.history, indent=1)
            )
        if self.verbose:
            print(f"eval @ {self.num_timesteps}: {json.dumps(flat, sort_keys=True)}")
        return summary

    def _due(self) -> bool:
        if self._next_eval_s is not None:
            if self.train_time_s() < self._next_eval_s:
                return False
            assert self.every_s is not None
            while self._next_eval_s <= self.train_time_s():
                self._next_eval_s += self.every_s
            return True
        return self.num_timesteps - self._last_eval >= self.eval_freq

    def _on_step(self) -> bool:
        if self._due():
            self._last_eval = self.num_timesteps
            self.evaluate_now()
            self.logger.dump(self.num_timesteps)
        return True


class FreezeActorCallback(BaseCallback):
    """Hold the actor still for the first ``warmup_steps`` env steps of RL fine-tuning.

    A cloned actor next to a fresh critic gets advantages from an untrained value function,
    and PPO's first updates undo the clone. Training only the critic first lets the value
    function catch up with the cloned behaviour before the actor moves.
    """

    def __init__(self, warmup_steps: int, verbose: int = 0) -> None:
        super().__init__(verbose)
        if warmup_steps < 0:
            raise ValueError(f"critic warm-up steps must be >= 0, got {warmup_steps}")
        self.warmup_steps = int(warmup_steps)
        self._frozen: list[Any] = []

    def _on_training_start(self) -> None:
        from baselines.agents.bc import actor_parameters

        if self.warmup_steps:
            self._frozen = actor_parameters(self.model)
            log_std = getattr(self.model.policy, "log_std", None)
            if log_std is not None:
                self._frozen.append(log_std)
            for p in self._frozen:
                p.requires_grad_(False)

    def _on_rollout_end(self) -> None:
        if self._frozen and self.num_timesteps >= self.warmup_steps:
            for p in self._frozen:
                p.requires_grad_(True)
            self._frozen = []

    def _on_step(self) -> bool:
        return True


class StatisticsCheckpointCallback(CheckpointCallback):
    """SB3's ``CheckpointCallback`` with the ``VecNormalize`` statistics in JSON
    (``<prefix>_vecnormalize_<N>_steps.json``, :mod:`baselines.models.normalization`), not a
    pickle."""

    def __init__(self, save_freq: int, save_path: str, name_prefix: str = "rl_model",
                 save_vecnormalize: bool = False) -> None:  # fmt: skip
        super().__init__(save_freq, save_path, name_prefix=name_prefix)
        self.save_statistics = save_vecnormalize

    def _on_step(self) -> bool:
        keep_going = super()._on_step()
        stats = self.model.get_vec_normalize_env()
        if self.save_statistics and stats is not None and self.n_calls % self.save_freq == 0:
            save_statistics(stats, self._checkpoint_path("vecnormalize_", extension="json"))
        return keep_going
