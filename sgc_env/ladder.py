"""The ladder of ids, easiest to hardest, as a table generated from the registered envs.

Spaces and body counts come from ``gym.make``, goal counts from the fixed scenario or the
random family's config, so the tables in ``docs/environments.md`` and ``README.md`` cannot
drift from the code: ``python -m sgc_env.ladder`` prints them and ``tests/sgc_env/test_ladder.py``
checks that the docs hold exactly what it prints.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from functools import cache
from typing import Any, cast

import gymnasium as gym

from sgc_env.scenes import PRESETS

__all__ = ["LADDER", "Rung", "goal_counts", "markdown", "short_markdown"]


@dataclass(frozen=True)
class Rung:
    """One id on the ladder and what it adds over the rung below."""

    env_id: str
    tests: str


LADDER: tuple[Rung, ...] = (
    Rung("SGCIntercept-v1", "meet a moving target exactly at its time; one scene, memorisable"),
    Rung(
        "SGCInterceptRandom-v1",
        "the same, with target path, meeting time and start state drawn per reset",
    ),
    Rung("SGCPoint-v1", "a routed sequence: exact and punctual at every goal, smooth through it"),
    Rung("SGCPointGoal-v1", "`SGCPoint-v1` as a goal-conditioned task (Dict observation, HER)"),
    Rung("SGCRod-v1", "position and orientation together: torques on a thin rod"),
    Rung(
        "SGCThreeRods-v2",
        "the paper's scene: three rods, long point-to-path sequences, tip goals, moving balls, "
        "a somersault; one scene",
    ),
    Rung(
        "SGCThreeRodsRandom-v3",
        "the same, with paths, goal counts, balls and times drawn per reset",
    ),
)


def _space(space: gym.Space) -> str:
    if isinstance(space, gym.spaces.Dict):
        sizes = (f"{k} {cast(tuple, v.shape)[0]}" for k, v in space.spaces.items())
        return "Dict(" + ", ".join(sizes) + ")"
    return f"Box ({cast(tuple, space.shape)[0]},)"


def _bodies(scenario) -> str:
    shapes = Counter(b.shape for b in scenario.bodies)
    return ", ".join(f"{n} {shape}{'s' if n > 1 else ''}" for shape, n in shapes.items())


def _family(env_id: str):
    """The random family an id is registered with, or None for a fixed scene."""
    name = gym.spec(env_id).kwargs.get("random_scenario")
    return PRESETS[name] if isinstance(name, str) else name


def goal_counts(env_id: str, scenario) -> str:
    """Goals per body: from the scenario (fixed) or the family's ranges (random)."""
    family = _family(env_id)
    if family is None:
        return "/".join(str(len(b.goals)) for b in scenario.bodies)
    return "/".join(str(lo) if lo == hi else f"{lo}-{hi}" for lo, hi in family.goal_counts())


def _row(rung: Rung) -> dict[str, str]:
    env = gym.make(rung.env_id)
    scenario = cast(Any, env.unwrapped).scenario
    row = {
        "id": f"`{rung.env_id}`",
        "bodies": _bodies(scenario),
        "observation": _space(env.observation_space),
        "action": _space(env.action_space),
        "goals": goal_counts(rung.env_id, scenario),
        "scenes": "fixed" if _family(rung.env_id) is None else "random",
        "tests": rung.tests,
    }
    env.close()
    return row


@cache
def _rows() -> tuple[dict[str, str], ...]:
    """One row per rung (making the random three-rod env draws a scene: made once)."""
    return tuple(_row(r) for r in LADDER)


def _table(columns: tuple[str, ...]) -> str:
    rows = _rows()
    lines = ["| rung | " + " | ".join(columns) + " |", "|---" * (len(columns) + 1) + "|"]
    lines += [
        f"| {i} | " + " | ".join(row[c] for c in columns) + " |" for i, row in enumerate(rows, 1)
    ]
    return "\n".join(lines)


def markdown() -> str:
    """The full ladder table (docs/environments.md)."""
    return _table(("id", "bodies", "observation", "action", "goals", "scenes", "tests"))


def short_markdown() -> str:
    """The short ladder table (README)."""
    return _table(("id", "bodies", "observation", "action", "goals", "scenes"))


if __name__ == "__main__":
    import sgc_env  # noqa: F401  (registers the ids)

    print(markdown())
    print()
    print(short_markdown())
