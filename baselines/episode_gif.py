"""A small GIF of one episode of a policy, for env cards and model cards.

Frames come from ``env.render()`` (the look of :mod:`sgc_env.render`, fixed camera), one every
``1 / fps`` s of episode time, written at real time with the demo's GIF writer (whole-
centisecond delays spread so the total is the episode's length).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, cast

import gymnasium as gym

__all__ = ["episode_gif"]


def episode_gif(env_id: str, policy: str, path: str | Path, *, seed: int = 0, width: int = 240,
                height: int = 180, fps: float = 10.0,
                env_kwargs: Mapping[str, Any] | None = None) -> Path:  # fmt: skip
    """Run ``policy`` (a spec of :func:`baselines.policies.make_policy`) for one episode from
    ``reset(seed=seed)`` and write its GIF to ``path``."""
    from baselines.cli.demo import _write_gif, gif_durations
    from baselines.evaluation import run_episode
    from baselines.policies import make_policy

    if fps <= 0:
        raise ValueError(f"fps: expected a positive number, got {fps!r}")
    env = gym.make(env_id, render_mode="rgb_array", width=width, height=height,
                   **dict(env_kwargs or {}))  # fmt: skip
    control_frequency = float(cast(Any, env.unwrapped).control_frequency)
    every = max(1, round(control_frequency / fps))
    frames: list[Any] = []

    def on_step(env_: Any, step: int, _info: Mapping[str, Any]) -> None:
        if step % every == 0:
            frames.append(env_.render())

    run_episode(make_policy(policy, env, seed=seed), env, seed=seed, on_step=on_step)
    env.close()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    real_fps = control_frequency / every
    _write_gif(out, frames, gif_durations(len(frames), real_fps))
    return out
