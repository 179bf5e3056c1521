"""Random interceptions: the ``intercept`` scene with its target path, meeting time and start
state drawn from the env's ``np_random`` on every reset.

A sphere (the "bird") starts at a drawn position and velocity, passes a drawn intermediate
nail (timed by routing) and must meet a kinematic target (the "fish", a piecewise-linear
path) at a drawn meeting time. Body, prop and limits are those of ``intercept.yaml``, so the
observation and action spaces are those of ``SGCIntercept-v1`` for every draw.

Feasibility: a draw is kept only if the analytic plan (``demand_bounds``, evaluated per
course: a few milliseconds) needs at most ``demand_share`` of the force limit; otherwise the
whole scene is redrawn. Tests run the expert inside PyBullet on the draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sgc_env.scenario import Body, Goal, Prop, Scenario, resolve_scenario
from sgc_env.scenario.demand import demand_bounds
from sgc_env.scenario.model import grid_time

__all__ = ["RandomInterceptConfig", "random_intercept"]

MAX_DRAWS = 1000


@dataclass(frozen=True)
class RandomInterceptConfig:
    """Ranges of the interception family (bird and fish geometry stay those of the fixed
    scene)."""

    start: tuple[float, float, float] = (0.0, 0.0, 2.0)
    start_spread: float = 0.5
    start_speed: tuple[float, float] = (0.0, 1.5)
    meeting_time: tuple[float, float] = (1.2, 2.5)
    fish_start: tuple[float, float, float] = (2.0, -0.5, 0.5)
    fish_spread: float = 0.6
    fish_speed: tuple[float, float] = (0.3, 1.5)
    fish_legs: int = 2
    via_fraction: tuple[float, float] = (0.3, 0.6)
    via_spread: float = 0.3
    bird_radius: float = 0.06
    bird_mass: float = 0.5
    force_limit: float = 30.0
    torque_limit: float = 1.0
    demand_share: float = 0.8
    """Largest share of the force limit the planned motion may need (|m (a - g)|, the norm):
    the expert's per-tick force can exceed the continuous plan's peak by a few percent."""
    control_frequency: int = 60
    margin: float = 0.25
    workspace: tuple[tuple[float, float, float], tuple[float, float, float]] = (
        (-6.0, -6.0, -5.0),
        (6.0, 6.0, 7.0),
    )

    def __post_init__(self) -> None:
        if not 0 < self.demand_share <= 1:
            raise ValueError(f"demand_share: expected (0, 1], got {self.demand_share}")
        for name in ("start_speed", "meeting_time", "fish_speed", "via_fraction"):
            a, b = getattr(self, name)
            if not 0 <= a <= b:
                raise ValueError(f"{name}: expected 0 <= low <= high, got {(a, b)}")
        if self.meeting_time[0] <= 0:
            raise ValueError(f"meeting_time: expected a positive low, got {self.meeting_time}")
        if self.fish_legs < 1:
            raise ValueError(f"fish_legs: expected >= 1, got {self.fish_legs}")
        if self.force_limit <= self.bird_mass * 9.81:
            raise ValueError(
                f"force_limit {self.force_limit} N must exceed the weight "
                f"{self.bird_mass * 9.81:.4g} N"
            )

    def draw(self, rng: np.random.Generator) -> Scenario:
        return random_intercept(rng, self)

    def goal_counts(self) -> tuple[tuple[int, int], ...]:
        """The bird's goals: the drawn intermediate nail and the meeting."""
        return ((2, 2),)

    def max_steps(self) -> int:
        """The meeting is the last goal: the latest meeting time plus the margin."""
        f = self.control_frequency
        return math.ceil(self.meeting_time[1] * f) + math.ceil(self.margin * f - 1e-9)


def _direction(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_intercept(
    rng: np.random.Generator, config: RandomInterceptConfig | None = None
) -> Scenario:
    """Draw one resolved, feasible interception from ``rng`` (redraws infeasible scenes)."""
    cfg = config or RandomInterceptConfig()
    for _ in range(MAX_DRAWS):
        scenario = _draw(rng, cfg)
        if scenario is None:
            continue
        ((force, _),) = demand_bounds(scenario, samples=64)
        if force <= cfg.demand_share * cfg.force_limit:
            return scenario
    raise RuntimeError(
        f"no feasible interception in {MAX_DRAWS} draws: widen meeting_time or force_limit"
    )


def _draw(rng: np.random.Generator, cfg: RandomInterceptConfig) -> Scenario | None:
    """One scene, or None when the meeting point is not 0.5 m inside the workspace."""
    f = cfg.control_frequency
    start = np.asarray(cfg.start) + rng.uniform(-cfg.start_spread, cfg.start_spread, 3)
    velocity = _direction(rng) * rng.uniform(*cfg.start_speed)
    meet = grid_time(rng.uniform(*cfg.meeting_time), f)
    # The fish swims in straight legs; its path outlasts the meeting time by the margin.
    leg_end = np.linspace(0.0, meet + cfg.margin + 0.5, cfg.fish_legs + 1)
    fish = [np.asarray(cfg.fish_start) + rng.uniform(-cfg.fish_spread, cfg.fish_spread, 3)]
    for dt in np.diff(leg_end):
        fish.append(fish[-1] + _direction(rng) * rng.uniform(*cfg.fish_speed) * dt)
    fish_at_meet = np.array([np.interp(meet, leg_end, [p[j] for p in fish]) for j in range(3)])
    low, high = np.asarray(cfg.workspace[0]) + 0.5, np.asarray(cfg.workspace[1]) - 0.5
    if not np.all((low <= fish_at_meet) & (fish_at_meet <= high)):
        return None
    via = start + rng.uniform(*cfg.via_fraction) * (fish_at_meet - start)
    via = via + rng.uniform(-cfg.via_spread, cfg.via_spread, 3)
    bird = Body(
        name="bird",
        shape="sphere",
        size=(cfg.bird_radius,),
        mass=cfg.bird_mass,
        position=_tuple(start),
        linear_velocity=_tuple(velocity),
        color=(0.9, 0.6, 0.1, 1.0),
        force_limit=cfg.force_limit,
        torque_limit=cfg.torque_limit,
        goals=(Goal(nail=_tuple(via)), Goal(nail_prop="fish", time=meet)),
    )
    prop = Prop(
        name="fish",
        shape="sphere",
        size=(0.08,),
        color=(0.1, 0.5, 0.9, 1.0),
        waypoints=tuple((float(t), _tuple(p)) for t, p in zip(leg_end, fish, strict=True)),
        collisions=False,
    )
    scenario = Scenario(
        bodies=(bird,),
        props=(prop,),
        name="intercept_random",
        workspace=cfg.workspace,
        margin=cfg.margin,
        control_frequency=f,
    )
    # random_intercept keeps a draw only under its own demand share (demand_bounds), so the
    # plan check of resolve_scenario would run the planner twice and raise instead of redraw.
    return resolve_scenario(scenario, check_plan=False)


def _tuple(v: np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
