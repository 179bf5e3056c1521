"""Wall-clock budgets: stop ``learn()`` once a run has trained for a fixed number of seconds.

SB3 ships step- and reward-based stops (``StopTrainingOnMaxEpisodes``,
``StopTrainingOnRewardThreshold``, ``StopTrainingOnNoModelImprovement``) but none on time. The
leaderboard compares algorithm families at one equal wall clock (issue 21), so every family
needs the same stop: :class:`TimeBudgetCallback`. Seconds spent in the harness's curve
evaluations (:class:`~baselines.agents.callbacks.HarnessEvalCallback`) do not count, for every
family alike, so a curve drawn more often does not shorten the training it draws.
"""

from __future__ import annotations

import math
import time
from typing import Any

from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.on_policy_algorithm import OnPolicyAlgorithm

__all__ = ["TimeBudgetCallback", "check_time_budget", "steps_learned", "whole_rollouts"]


def check_time_budget(value: Any, where: str = "time_budget_s") -> float | None:
    """``None`` (no budget) or a finite number of seconds > 0; anything else is a ValueError."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where}: expected a number of seconds, got {value!r}")
    seconds = float(value)
    if not math.isfinite(seconds) or seconds <= 0:
        raise ValueError(f"{where}: expected a finite number of seconds > 0, got {value!r}")
    return seconds


def whole_rollouts(timesteps: int, algo: str, hp: Any) -> int:
    """``timesteps`` rounded up to what SB3 really trains with hyperparameters ``hp``
    (:class:`~baselines.agents.hyperparams.Hyperparams`): PPO collects whole rollouts of
    ``n_steps`` per env, the off-policy algorithms one step per env at a time."""
    chunk = hp.n_envs * (int(hp.algo_kwargs.get("n_steps", 2048)) if algo == "ppo" else 1)
    return -(-timesteps // chunk) * chunk


def steps_learned(model: Any, stopped: bool) -> int | None:
    """The ``--timesteps`` of the fixed-step run with the same parameters as ``model``.

    SB3 checks callbacks after each env step, and a stop there skips the update those steps
    were collected for: PPO drops its unfinished rollout (it learns from whole rollouts of
    ``n_steps x n_envs``), SAC/TD3 the gradient steps of the last ``train_freq`` chunk. So a
    run the budget ``stopped`` took ``model.num_timesteps`` env steps but learned from fewer;
    None where SB3 counts ``train_freq`` in episodes (no fixed-step equivalent).
    """
    steps = int(model.num_timesteps)
    if not stopped:
        return steps
    n_envs = int(model.n_envs)
    if isinstance(model, OnPolicyAlgorithm):  # whole rollouts
        chunk = int(model.n_steps) * n_envs
    else:
        freq = model.train_freq
        if getattr(freq.unit, "value", "step") != "step":
            return None
        chunk = int(freq.frequency) * n_envs
    # the stop came after the step that ends at ``steps``: its chunk was not learned from,
    # even when that step completed it
    return max(steps - n_envs, 0) // chunk * chunk


class TimeBudgetCallback(BaseCallback):
    """Stop training once ``budget_s`` seconds of training have passed since ``started``.

    ``started`` (a ``time.perf_counter()`` reading) lets time spent before ``learn()`` count, such
    as behaviour cloning and DAgger; by default the clock starts with training. ``excluded``
    objects with an ``eval_time_s`` attribute (the curve evaluations) have their seconds taken
    off. The check runs after every env step (one ``VecEnv.step`` of all sub-envs), so a run
    overshoots by at most one step plus, for PPO, one update phase.
    """

    def __init__(
        self,
        budget_s: float,
        started: float | None = None,
        excluded: tuple[Any, ...] = (),
        verbose: int = 0,
    ) -> None:
        super().__init__(verbose)
        seconds = check_time_budget(budget_s, "budget_s")
        if seconds is None:
            raise ValueError("budget_s: expected a number of seconds, got None")
        self.budget_s: float = seconds
        self.started = started
        self.excluded = excluded
        self.spent_out = False

    def elapsed(self) -> float:
        """Seconds of training so far (curve evaluations taken off)."""
        if self.started is None:
            return 0.0
        off = sum(float(getattr(x, "eval_time_s", 0.0)) for x in self.excluded)
        return time.perf_counter() - self.started - off

    def spent(self) -> bool:
        """True once the budget is used up (also before ``learn()``, by cloning)."""
        self.spent_out = self.spent_out or self.elapsed() >= self.budget_s
        return self.spent_out

    def _on_training_start(self) -> None:
        if self.started is None:
            self.started = time.perf_counter()

    def _on_step(self) -> bool:
        if self.spent():
            if self.verbose:
                print(f"time budget of {self.budget_s:g} s spent at {self.num_timesteps} steps")
            return False
        return True
