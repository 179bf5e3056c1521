"""Random feasible scenarios drawn from the env's own ``np_random``.

Course directions turn by at most ``max_turn_angle``, course lengths and average speeds are
drawn from ranges, and a share of the intermediate goals is time-critical (the others are
timed by routing weights equal to their drawn speeds, so routing reproduces the drawn rhythm).
Feasibility: the force/torque limits are constants of the config (an agent does not observe
them, so the action scale must not change between episodes); speeds and rotation angles are
drawn below caps that keep a conservative bound of what an SGC course needs inside those limits
(see ``_ACCEL_FACTOR``). The tests check the bound against the analytic plan
(:func:`~sgc_env.scenario.demand.demand_bounds`) rather than every reset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sgc_env.scenario import Body, Goal, Scenario, resolve_scenario
from sgc_env.scenario.demand import inertia_diagonal
from sgc_env.scenario.model import grid_time

__all__ = ["RandomScenarioConfig", "draw_courses"]

# Conservative need of an SGC course: acceleration _ACCEL_FACTOR * (average speed of the course
# + of the one before) / duration, angular acceleration _ACCEL_FACTOR * angle / duration^2.
# Against sgc_env.paper.plan on 120 random draws the plan's peak stayed below 0.93 of the bound
# with factor 24; 30 adds margin. tests/sgc_env/scenario/test_scenario.py re-checks it with the
# planner.
_ACCEL_FACTOR = 30.0


@dataclass(frozen=True)
class RandomScenarioConfig:
    """Ranges for random scenarios of one body kind (shape, size and mass stay fixed)."""

    shape: str = "sphere"
    size: tuple[float, ...] = (0.05,)
    mass: float = 1.0
    n_goals: tuple[int, int] = (3, 3)
    spacing: tuple[float, float] = (0.3, 0.8)
    speed: tuple[float, float] = (0.5, 1.5)
    max_turn_angle: float = math.pi / 3
    critical_share: float = 0.5
    orientation: bool = False
    max_rotation: float = math.pi / 2
    control_frequency: int = 60
    margin: float = 0.25
    start: tuple[float, float, float] = (0.0, 0.0, 1.0)
    workspace_half_width: float = 10.0
    force_limit: float = 100.0
    torque_limit: float = 3.0

    def __post_init__(self) -> None:
        lo, hi = self.n_goals
        if not 1 <= lo <= hi:
            raise ValueError(f"n_goals: expected 1 <= low <= high, got {self.n_goals}")
        for name in ("spacing", "speed"):
            a, b = getattr(self, name)
            if not 0 < a <= b:
                raise ValueError(f"{name}: expected 0 < low <= high, got {(a, b)}")
        if not 0 <= self.max_turn_angle <= math.pi:
            raise ValueError(f"max_turn_angle: expected [0, pi], got {self.max_turn_angle}")
        if not 0 <= self.critical_share <= 1:
            raise ValueError(f"critical_share: expected [0, 1], got {self.critical_share}")
        if self.force_limit <= self.mass * 9.81 or self.torque_limit <= 0:
            raise ValueError(
                f"force_limit {self.force_limit} N must exceed the weight {self.mass * 9.81:.4g} N"
                f" and torque_limit {self.torque_limit} N m must be positive"
            )

    def draw(self, rng: np.random.Generator) -> Scenario:
        return draw_courses(rng, self)

    def goal_counts(self) -> tuple[tuple[int, int], ...]:
        """Fewest and most goals of the (one) body."""
        return (self.n_goals,)

    def max_steps(self) -> int:
        """Mirrors :func:`draw_courses`: a course of length ``L`` is flown at no less than
        ``min(speed_low, cap)``, where ``cap`` (the speed the force budget allows after a course
        flown at ``v_prev``) grows with ``L`` slower than ``L`` and falls with ``v_prev``; so
        ``L / speed`` is largest for the longest course after the fastest one."""
        f = self.control_frequency
        length, v_prev = self.spacing[1], self.speed[1]
        cap = _speed_cap(self, length, v_prev)
        slowest = min(self.speed[0], cap)
        course = max(6, math.ceil(length / slowest * f + 1e-6))
        return self.n_goals[1] * course + math.ceil(self.margin * f - 1e-9)


def _accel_budget(cfg: RandomScenarioConfig) -> float:
    """Acceleration the force limit leaves after gravity, with 10 % slack for routed times
    moving by up to half a tick."""
    return 0.9 * (cfg.force_limit / cfg.mass - 9.81)


def _speed_cap(cfg: RandomScenarioConfig, length: float, prev_speed: float) -> float:
    """Largest speed with ``_ACCEL_FACTOR * (v + v_prev) * v / length <= accel budget``."""
    budget = _accel_budget(cfg)
    return 0.5 * (-prev_speed + math.sqrt(prev_speed**2 + 4 * budget * length / _ACCEL_FACTOR))


def _largest_moment(cfg: RandomScenarioConfig) -> float:
    return float(inertia_diagonal(cfg.shape, cfg.size, cfg.mass).max())


def _turn(rng: np.random.Generator, direction: np.ndarray, max_angle: float) -> np.ndarray:
    """A unit vector at a random angle <= max_angle from ``direction``."""
    helper = rng.normal(size=3)
    perp = helper - helper.dot(direction) * direction
    perp /= np.linalg.norm(perp)
    angle = rng.uniform(0.0, max_angle)
    return math.cos(angle) * direction + math.sin(angle) * perp


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def draw_courses(rng: np.random.Generator, cfg: RandomScenarioConfig) -> Scenario:
    """Draw one resolved, feasible single-body scenario of ``cfg`` from ``rng``."""
    f = cfg.control_frequency
    n = int(rng.integers(cfg.n_goals[0], cfg.n_goals[1] + 1))
    start = np.asarray(cfg.start, float)
    angle_budget = 0.9 * cfg.torque_limit / (_ACCEL_FACTOR * _largest_moment(cfg))
    direction = _unit(rng)
    point = start.copy()
    t, prev_speed = 0.0, 0.0
    goals = []
    for i in range(n):
        if i:
            direction = _turn(rng, direction, cfg.max_turn_angle)
        length = rng.uniform(*cfg.spacing)
        hi = min(cfg.speed[1], _speed_cap(cfg, length, prev_speed))
        speed = rng.uniform(min(cfg.speed[0], hi), hi)
        ticks = max(6, math.ceil(length / speed * f))
        duration = ticks / f
        prev_speed = length / duration
        point = point + length * direction
        t = t + duration
        critical = i == n - 1 or bool(rng.random() < cfg.critical_share)
        rel = None
        if cfg.orientation:
            top = min(cfg.max_rotation, angle_budget * duration**2)
            angle = rng.uniform(min(0.2, top), top)
            rel = tuple(float(x) for x in _unit(rng) * angle)
        goals.append(
            Goal(
                nail=tuple(float(x) for x in point),  # type: ignore[arg-type]
                relative_rotation=rel,  # type: ignore[arg-type]
                time=grid_time(t, f) if critical else None,
                critical=critical,
                weight=length / duration,
            )
        )
    body = Body(
        name="body0",
        shape=cfg.shape,
        size=cfg.size,
        mass=cfg.mass,
        position=tuple(float(x) for x in start),  # type: ignore[arg-type]
        force_limit=cfg.force_limit,
        torque_limit=cfg.torque_limit,
        goals=tuple(goals),
    )
    hw = cfg.workspace_half_width
    scenario = Scenario(
        bodies=(body,),
        name="random",
        workspace=(tuple(start - hw), tuple(start + hw)),
        margin=cfg.margin,
        control_frequency=f,
    )
    # The caps above bound what the plan needs; running the planner check here would cost
    # 0.1-0.3 s per reset (measured on both presets), so tests check the bound instead.
    return resolve_scenario(scenario, check_plan=False)
