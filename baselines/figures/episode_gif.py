"""A small GIF of one episode of a policy, for env cards and model cards.

Frames come from ``env.render()`` (the look of :mod:`sgc_env.render`, fixed camera), one every
``1 / fps`` s of episode time, written at real time by :func:`write_gif` (whole-centisecond
delays spread by :func:`gif_durations` so the total is the episode's length; ``sgc demo``
writes its GIF with them too).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np

__all__ = ["episode_gif", "gif_durations", "write_gif"]


def gif_durations(count: int, fps: float) -> list[int]:
    """Per-frame GIF delays (ms) summing to real time: GIF delays are whole centiseconds, so
    a 1000/fps delay that is not one is spread (66.7 ms -> 70, 70, 60)."""
    ends = np.round(np.arange(1, count + 1) * 100.0 / fps).astype(int) * 10
    return np.diff(np.r_[0, ends]).tolist()


def write_gif(path: Path, frames: Sequence[np.ndarray], durations: Sequence[int]) -> None:
    """Pillow GIF with a fast octree palette per frame (median cut costs ~3x the CPU)."""
    from PIL import Image

    images = [
        Image.fromarray(f).quantize(256, method=Image.Quantize.FASTOCTREE,
                                    dither=Image.Dither.FLOYDSTEINBERG)
        for f in frames
    ]  # fmt: skip
    images[0].save(path, save_all=True, append_images=images[1:], duration=list(durations),
                   loop=0, optimize=False)  # fmt: skip


def episode_gif(env_id: str, policy: str, path: str | Path, *, seed: int = 0, width: int = 240,
                height: int = 180, fps: float = 10.0,
                env_kwargs: Mapping[str, Any] | None = None) -> Path:  # fmt: skip
    """Run ``policy`` (a spec of :func:`baselines.policies.make_policy`) for one episode from
    ``reset(seed=seed)`` and write its GIF to ``path``."""
    from baselines.evaluation.harness import run_episode
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
    write_gif(out, frames, gif_durations(len(frames), real_fps))
    return out
