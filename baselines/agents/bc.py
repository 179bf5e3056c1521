"""Behaviour cloning and DAgger into an SB3 model's actor.

The ``imitation`` library (1.0.1) pins gymnasium ~0.29 and stable-baselines3 ~2.2, so it does
not install next to this stack; a short torch loop does the job. Cloning regresses the
actor's *deterministic* action (PPO: the Gaussian mean; SAC: tanh of the mean; TD3: the actor
output) onto the expert's action with MSE, which is what ``predict(deterministic=True)`` and
the scoring harness use. DAgger (Ross et al. 2011) then rolls the clone out, labels the states
it visits with the expert and refits, because a plain clone drifts off the expert's state
distribution and the expert's feedback is what corrects that drift.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, cast

import gymnasium as gym
import numpy as np
import torch as th
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.policies import ActorCriticPolicy

from baselines.agents.demos import Demonstrations
from baselines.agents.pushes import Pushes, apply_random_push, push_rng

__all__ = ["BCResult", "actor_parameters", "behaviour_clone", "dagger", "deterministic_actions"]


@dataclass
class BCResult:
    """Mean MSE per epoch (and per DAgger round: dataset size and final loss)."""

    epoch_losses: list[float] = field(default_factory=list)
    rounds: list[dict[str, float]] = field(default_factory=list)


def deterministic_actions(model: BaseAlgorithm, obs: th.Tensor) -> th.Tensor:
    """Differentiable deterministic action of the model's actor (before clipping)."""
    policy = model.policy
    if isinstance(policy, ActorCriticPolicy):
        distribution: Any = policy.get_distribution(obs).distribution  # one Normal here
        return distribution.mean
    actor = getattr(policy, "actor", None)
    if actor is None:
        raise ValueError(f"algo: cannot clone into {type(model).__name__}: no actor")
    try:
        return actor(obs, deterministic=True)
    except TypeError:
        return actor(obs)


def actor_parameters(model: BaseAlgorithm) -> list[th.nn.Parameter]:
    """Parameters that shape the deterministic action (not the critic's)."""
    policy = model.policy
    if isinstance(policy, ActorCriticPolicy):
        skip = {id(p) for p in policy.value_net.parameters()}
        value_net: Any = policy.mlp_extractor.value_net
        skip |= {id(p) for p in value_net.parameters()}
        skip.add(id(policy.log_std))
        return [p for p in policy.parameters() if id(p) not in skip]
    return list(cast(Any, policy).actor.parameters())


def _sync_targets(model: BaseAlgorithm) -> None:
    """TD3 keeps a target actor; it must start from the clone too."""
    target = getattr(model, "actor_target", None)
    if target is not None:
        target.load_state_dict(cast(Any, model).actor.state_dict())


def behaviour_clone(
    model: BaseAlgorithm,
    demos: Demonstrations,
    epochs: int = 30,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    seed: int = 0,
    log_std: float | None = -2.0,
) -> BCResult:
    """Fit the actor of ``model`` to ``demos`` (MSE on the deterministic action).

    Adam with the learning rate decaying linearly to a tenth: the expert's feedback law has
    large gains near goal ticks, and the small late steps are what bring the error down there.

    ``log_std`` (PPO only) sets the exploration noise of the clone so that RL fine-tuning
    starts close to the cloned behaviour instead of SB3's unit standard deviation.
    """
    if epochs < 1 or batch_size < 1:
        raise ValueError(f"bc: epochs and batch_size must be >= 1, got {epochs}, {batch_size}")
    obs_space = model.observation_space
    if not isinstance(obs_space, gym.spaces.Box) or demos.observations.shape[1:] != obs_space.shape:
        raise ValueError(
            f"demos: observations of shape {demos.observations.shape[1:]} do not fit the "
            f"model's observation space {obs_space}"
        )
    if demos.actions.shape[1:] != model.action_space.shape:
        raise ValueError(
            f"demos: actions of shape {demos.actions.shape[1:]} do not fit {model.action_space}"
        )
    device = model.device
    obs = th.as_tensor(demos.observations, dtype=th.float32, device=device)
    target = th.as_tensor(np.clip(demos.actions, -1.0, 1.0), dtype=th.float32, device=device)
    params = actor_parameters(model)
    optimizer = th.optim.Adam(params, lr=learning_rate)
    updates = epochs * -(-len(obs) // batch_size)
    decay = th.optim.lr_scheduler.LambdaLR(optimizer, lambda k: 1.0 - 0.9 * k / updates)
    generator = th.Generator().manual_seed(seed)
    model.policy.set_training_mode(True)
    result = BCResult()
    n = len(obs)
    for _ in range(epochs):
        order = th.randperm(n, generator=generator).to(device)
        total = 0.0
        for start in range(0, n, batch_size):
            idx = order[start : start + batch_size]
            loss = th.nn.functional.mse_loss(deterministic_actions(model, obs[idx]), target[idx])
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
            decay.step()
            total += loss.item() * len(idx)
        result.epoch_losses.append(total / n)
    model.policy.set_training_mode(False)
    if log_std is not None and isinstance(model.policy, ActorCriticPolicy):
        with th.no_grad():
            model.policy.log_std.fill_(log_std)
    _sync_targets(model)
    return result


def imitation_loss(model: BaseAlgorithm, demos: Demonstrations) -> float:
    """MSE of the model's deterministic action against the demos (no gradient)."""
    with th.no_grad():
        obs = th.as_tensor(demos.observations, dtype=th.float32, device=model.device)
        target = th.as_tensor(np.clip(demos.actions, -1, 1), dtype=th.float32, device=model.device)
        return float(th.nn.functional.mse_loss(deterministic_actions(model, obs), target))


def _label_rollouts(
    model: BaseAlgorithm, env: gym.Env, expert: Any, seeds: np.ndarray, pushes: Pushes
) -> tuple[np.ndarray, np.ndarray]:
    """States visited by the model's deterministic policy, labelled with the expert's action
    (on a learner's id: its action on the env's planner view of the state, through
    :func:`~baselines.policies.make_policy`).

    A push replaces the state before it is labelled, so the expert's recovery is learned.
    """
    states, labels = [], []
    for s in seeds:
        obs, _ = env.reset(seed=int(s))
        rng, tick, done = push_rng(int(s)), 0, False
        while not done:
            obs = apply_random_push(env, obs, pushes, rng, tick)
            states.append(obs)
            labels.append(np.clip(expert.predict(obs, deterministic=True)[0], -1.0, 1.0))
            action, _ = model.predict(obs, deterministic=True)
            obs, _, terminated, truncated, _ = env.step(action)
            done, tick = terminated or truncated, tick + 1
    return np.asarray(states, np.float32), np.asarray(labels, np.float32)


def dagger(
    model: BaseAlgorithm,
    demos: Demonstrations,
    rounds: int,
    episodes_per_round: int,
    seed: int,
    epochs: int = 10,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    log_std: float | None = -2.0,
    pushes: Pushes | None = None,
    deadline: float | None = None,
) -> tuple[Demonstrations, BCResult]:
    """``rounds`` of: roll out the clone, relabel with the expert, refit on the aggregate.

    Rollout seeds are ``seed + 1_000_000 + r * episodes_per_round + i`` so they never overlap
    the demonstration or held-out evaluation seeds. ``pushes`` knock the clone off its own
    path during the rollouts (see :mod:`baselines.agents.pushes`); the default pushes nothing.
    No round starts once ``time.perf_counter()`` has passed ``deadline`` (a wall-clock budget).
    """
    from baselines.policies import make_policy

    if rounds < 0 or episodes_per_round < 1:
        raise ValueError(
            f"dagger: rounds >= 0 and episodes >= 1, got {rounds}, {episodes_per_round}"
        )
    result = BCResult()
    env = gym.make(demos.env_id, **demos.env_kwargs)
    try:
        expert = make_policy("expert", env)
        for r in range(rounds):
            if deadline is not None and time.perf_counter() >= deadline:
                break
            first = seed + 1_000_000 + r * episodes_per_round
            seeds = np.arange(first, first + episodes_per_round)
            states, labels = _label_rollouts(model, env, expert, seeds, pushes or Pushes())
            demos = demos.extend(states, labels)
            fit = behaviour_clone(
                model, demos, epochs=epochs, batch_size=batch_size,
                learning_rate=learning_rate, seed=seed + r, log_std=log_std,
            )  # fmt: skip
            result.epoch_losses.extend(fit.epoch_losses)
            result.rounds.append({"round": r, "samples": len(demos), "loss": fit.epoch_losses[-1]})
    finally:
        env.close()
    return demos, result
