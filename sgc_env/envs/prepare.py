"""A scenario checked against an env and compiled, before the env changes.

Why a step of its own: ``reset(options={"scenario": ...})`` and random draws must leave the env
exactly as it was when a scenario is rejected, so everything that can fail (body count, action
size, control frequency, the shared world's rules, compiling the tracks and prop paths) runs here
and the env commits the result in one go (``SGCEnv._commit``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from sgc_env.episode_steps import scenario_steps
from sgc_env.scenario import Scenario, load_scenario

from .props import PropPaths
from .task import GoalTask
from .vector.world import SharedWorld

__all__ = ["Prepared", "as_scenario", "prepare_scenario", "scene_geometry"]


@dataclass(frozen=True)
class Prepared:
    """A scenario checked against an env, with what it compiles to."""

    scenario: Scenario
    task: GoalTask
    max_steps: int
    props: PropPaths


def as_scenario(spec: Scenario | str | Path) -> Scenario:
    """A scenario object from a scenario, a built-in name or a YAML path."""
    return spec if isinstance(spec, Scenario) else load_scenario(spec)


def scene_geometry(s: Scenario) -> tuple:
    """What PyBullet bodies a scene needs: equal geometries reuse the bodies at a reset."""
    return (
        tuple((b.name, b.shape, b.size, b.mass, b.color, b.collisions) for b in s.bodies),
        tuple((p.name, p.shape, p.size, p.color, p.collisions) for p in s.props),
    )


def prepare_scenario(
    s: Scenario,
    *,
    n_bodies: int,
    use_torque: bool,
    control_frequency: int,
    sim_frequency: int,
    world: SharedWorld | None,
) -> Prepared:
    """Check ``s`` against an env made for ``n_bodies`` bodies and compile its tracks."""
    if len(s.bodies) != n_bodies:
        raise ValueError(f"scenario has {len(s.bodies)} bodies, this env was made for {n_bodies}")
    needs_torque = not all(b.shape == "sphere" and not b.has_orientation_track for b in s.bodies)
    if needs_torque and not use_torque:
        raise ValueError("scenario needs torques but this env's action space has forces only")
    if s.control_frequency != control_frequency:
        raise ValueError(
            f"scenario control_frequency {s.control_frequency} Hz differs from the env's "
            f"{control_frequency} Hz"
        )
    if world is not None:
        world.check_scenario(s)
    max_steps = scenario_steps(s)  # the registry's max_episode_steps counts the same
    substeps = sim_frequency // control_frequency
    props = PropPaths(s.props, sim_frequency, (max_steps + 1) * substeps)
    return Prepared(s, GoalTask(s), max_steps, props)
