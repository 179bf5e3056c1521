"""The env step of two checkouts in one process, interleaved: is a refactor's hot path as fast?

Imports ``sgc_env`` of a reference checkout (another worktree, e.g. ``git worktree add
/tmp/base <commit>``), keeps its env class, then imports the installed ``sgc_env`` in its
place. For each id both envs run the same scenario under a hover action in alternating chunks
(the order flipped every round), and a bare PyBullet loop of the new env's physics runs in the
same rounds: the fixed reference that neither checkout can slow down. The best chunk per side
is kept, in wall and in process CPU time, so a busy, shared machine only ever slows a chunk
down and both sides see the same machine.
"""

from __future__ import annotations

import importlib
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from baselines.timing.bare import BareLoop, hover_action

__all__ = ["compare_checkouts", "load_sgc_env"]


def load_sgc_env(checkout: Path | None) -> Any:
    """``sgc_env`` imported from ``checkout`` (None: the installed one), after forgetting any
    other copy's modules."""
    for name in [m for m in sys.modules if m == "sgc_env" or m.startswith("sgc_env.")]:
        del sys.modules[name]
    if checkout is not None:
        sys.path.insert(0, str(checkout))
    try:
        package = importlib.import_module("sgc_env")
        importlib.import_module("sgc_env.envs")
    finally:
        if checkout is not None:
            sys.path.remove(str(checkout))
    return package


def _chunk_us(env: Any, steps: int, action: np.ndarray) -> tuple[float, float]:
    """(wall, CPU) microseconds per env.step over ``steps`` steps (resets included, rare)."""
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset(options={"scenario": env.scenario})
    return (time.perf_counter() - wall) / steps * 1e6, (time.process_time() - cpu) / steps * 1e6


def _fixed_env(package: Any, kwargs: dict[str, Any]) -> Any:
    """An SGCEnv of ``package`` on the scenario the registered kwargs give at seed 0."""
    made = package.envs.SGCEnv(**kwargs)
    made.reset(seed=0)
    view = {k: v for k, v in kwargs.items() if k in ("observation", "reward")}
    env = package.envs.SGCEnv(made.scenario, **view)  # the id's view and reward cost per step
    made.close()
    env.reset()
    return env


def compare_checkouts(
    reference: Path, pairs: list[tuple[str, str]] | None, rounds: int, chunk: int
) -> Iterator[str]:
    """The comparison's lines, one per pair in order. ``pairs``: (this checkout's id, the
    reference's id: the same id, or another version of the same task on the same scene);
    None: every id both register."""
    ref = load_sgc_env(reference)
    new = load_sgc_env(None)
    if pairs is None:
        pairs = [(k, k) for k, v in new._REGISTRY.items()
                 if v[0].endswith(":SGCEnv") and k in ref._REGISTRY]  # fmt: skip
    for newest, old in pairs:
        if newest not in new._REGISTRY or old not in ref._REGISTRY:
            raise ValueError(f"{newest}={old}: NEW must be registered here and OLD at {reference}")
    yield (
        f"{'id':18} {'ref us/step':>12} {'new us/step':>12} {'wall new/ref':>13} "
        f"{'ref cpu us':>11} {'new cpu us':>11} {'cpu new/ref':>12} {'bare us':>8} {'new/bare':>9}"
    )
    for newest, old in pairs:
        envs = {"ref": _fixed_env(ref, ref._REGISTRY[old][1]),
                "new": _fixed_env(new, new._REGISTRY[newest][1])}  # fmt: skip
        action = hover_action(envs["new"])
        bare = BareLoop(envs["new"])
        best = {side: [float("inf"), float("inf")] for side in envs}
        best_bare = float("inf")
        for r in range(rounds):
            for side in ("ref", "new") if r % 2 == 0 else ("new", "ref"):  # ABBA: no order bias
                wall, cpu = _chunk_us(envs[side], chunk, action)
                best[side] = [min(best[side][0], wall), min(best[side][1], cpu)]
            best_bare = min(best_bare, bare.run_us(chunk))
        bare.close()
        for env in envs.values():
            env.close()
        (rw, rc), (nw, nc) = best["ref"], best["new"]
        name = newest if newest == old else f"{newest}={old}"
        yield (
            f"{name:18} {rw:12.1f} {nw:12.1f} {nw / rw:13.3f} {rc:11.1f} {nc:11.1f} "
            f"{nc / rc:12.3f} {best_bare:8.1f} {nw / best_bare:9.2f}"
        )
