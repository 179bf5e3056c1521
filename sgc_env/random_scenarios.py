"""Random feasible scenarios drawn from the env's own ``np_random``.

Course directions turn by at most ``max_turn_angle``, course lengths and average speeds are
drawn from ranges, and a share of the intermediate goals is time-critical (the others are
timed by routing weights equal to their drawn speeds, so routing reproduces the drawn rhythm).
Feasibility: the force/torque limits are constants of the config (an agent does not observe
them, so the action scale must not change between episodes); speeds and rotation angles are
drawn below caps that keep a conservative bound of what an SGC course needs inside those limits
(see ``_ACCEL_FACTOR``). ``planner_demand`` checks the bound against the analytic planner in the
tests rather than on every reset (the plan costs milliseconds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np

from sgc_env.random_intercept import RandomInterceptConfig
from sgc_env.random_three_rods import RandomThreeRodsConfig
from sgc_env.scenario import Body, Goal, Scenario, resolve_scenario

__all__ = ["PRESETS", "RandomScenarioConfig", "planner_demand", "random_scenario"]

# Conservative need of an SGC course: acceleration _ACCEL_FACTOR * (average speed of the course
# + of the one before) / duration, angular acceleration _ACCEL_FACTOR * angle / duration^2.
# Against sgc_env.paper.plan on 120 random draws the plan's peak stayed below 0.93 of the bound
# with factor 24; 30 adds margin. tests/test_scenario.py re-checks it with the planner.
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

    def goal_counts(self) -> tuple[tuple[int, int], ...]:
        """Fewest and most goals of the (one) body."""
        return (self.n_goals,)


SceneFamily = RandomScenarioConfig | RandomInterceptConfig | RandomThreeRodsConfig
"""A config the env can redraw from on every reset; families other than the single-body
:class:`RandomScenarioConfig` draw through their own ``draw(rng)``."""

PRESETS: dict[str, SceneFamily] = {
    "point": RandomScenarioConfig(),
    "rod": RandomScenarioConfig(shape="rod", size=(0.6, 0.03), orientation=True),
    "intercept": RandomInterceptConfig(),
    "three_rods": RandomThreeRodsConfig(),
}


def ticks_to_time(t: float, frequency: int) -> float:
    """``t`` rounded to the control grid (exact multiple of 1/frequency)."""
    return round(t * frequency) / frequency


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


def _inertia_bound(cfg: RandomScenarioConfig) -> float:
    """Largest principal moment of the body (solid sphere, cylinder, box)."""
    m = cfg.mass
    if cfg.shape == "sphere":
        return 0.4 * m * cfg.size[0] ** 2
    if cfg.shape == "rod":
        length, r = cfg.size
        return m * (3 * r * r + length * length) / 12.0
    hx, hy, hz = cfg.size
    return m * 4 * max(hx * hx + hy * hy, hy * hy + hz * hz, hx * hx + hz * hz) / 12.0


def random_scenario(rng: np.random.Generator, config: SceneFamily | str = "point") -> Scenario:
    """Draw one resolved, feasible scenario of a preset or family from ``rng``."""
    cfg = PRESETS[config] if isinstance(config, str) else config
    if not isinstance(cfg, RandomScenarioConfig):
        return cfg.draw(rng)
    f = cfg.control_frequency
    n = int(rng.integers(cfg.n_goals[0], cfg.n_goals[1] + 1))
    start = np.asarray(cfg.start, float)
    # Budgets with 10 % slack for routed times moving by up to half a tick.
    accel_budget = 0.9 * (cfg.force_limit / cfg.mass - 9.81)
    angle_budget = 0.9 * cfg.torque_limit / (_ACCEL_FACTOR * _inertia_bound(cfg))
    direction = _unit(rng)
    point = start.copy()
    t, prev_speed = 0.0, 0.0
    goals = []
    for i in range(n):
        if i:
            direction = _turn(rng, direction, cfg.max_turn_angle)
        length = rng.uniform(*cfg.spacing)
        # Largest speed with _ACCEL_FACTOR * (v + v_prev) * v / length <= accel_budget.
        cap = 0.5 * (
            -prev_speed + math.sqrt(prev_speed**2 + 4 * accel_budget * length / _ACCEL_FACTOR)
        )
        hi = min(cfg.speed[1], cap)
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
                time=ticks_to_time(t, f) if critical else None,
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


def planner_demand(scenario: Scenario, samples: int = 64) -> list[tuple[float, float]]:
    """Upper bounds of the peak |force| and |torque| per body along the analytic SGC plan.

    Sampled on every course of both tracks (``samples`` times each, both ends included), one
    vectorised evaluation per course (``BodyPlan.deviations``): a few milliseconds per body
    after planning, cheap enough for the random families to check every draw. With ``p''`` the
    tracked point's acceleration, ``r`` its largest offset from the centre of mass and ``phi``
    the orientation deviation (``omega = J_l(phi) phi'``, ``|J_l| <= 1``)::

        |omega| <= |phi'|,   |omega'| <= |phi''| + j(|phi|) |phi'|^2,   spin = |omega'| + |omega|^2
        force  <= m (|p'' - g| + r spin),   torque <= I_max spin   (gyroscopic term included)

    where ``j(theta) = (theta e^theta - e^theta + 1) / theta^2`` bounds the rate of ``J_l``
    (its series, term by term). Without an orientation track ``omega`` is the constant
    initial one. The torque action ``R0 diag(1 / torque_scale) R0^T tau`` has principal
    components ``(I_k alpha_k + gyro_k) / (torque_limit I_k / I_max)`` and
    ``|gyro_k| <= I_k |omega_j omega_l|`` (principal moments obey ``I_k >= |I_j - I_l|``), so its
    norm, and every entry, stays below ``torque / torque_limit``: a torque bound below
    ``torque_limit`` keeps the scaled torque action inside the box.
    """
    from sgc_env.paper.plan import BodyState, OrientationGoal, PlanOptions, PositionGoal, plan_body

    g = np.asarray(scenario.gravity, float)
    grid = np.linspace(1e-9, 1.0, samples)
    out = []
    for b in scenario.bodies:
        plan = plan_body(
            BodyState(
                np.asarray(b.position), np.asarray(b.orientation),
                np.asarray(b.linear_velocity), np.asarray(b.angular_velocity),
            ),
            [PositionGoal(cast(float, gl.time), np.asarray(gl.nail), np.asarray(gl.point))
             for gl in b.goals if gl.has_position],
            [OrientationGoal(cast(float, gl.time), orientation=None if gl.orientation is None
                             else np.asarray(gl.orientation),
                             relative_rotation=None if gl.relative_rotation is None
                             else np.asarray(gl.relative_rotation))
             for gl in b.goals if gl.has_orientation],
            end_velocity=b.end_velocity, end_angular_velocity=b.end_angular_velocity,
            options=PlanOptions(control_frequency=scenario.control_frequency),
        )  # fmt: skip
        times = np.concatenate([c.t_start + (c.t_end - c.t_start) * grid for c in plan.courses])
        accel = plan.deviations(times, "position")[2]
        if b.has_orientation_track:
            phi, phi_dot, phi_ddot = plan.deviations(times, "orientation")
            w2 = np.sum(phi_dot**2, axis=1)
            theta = np.linalg.norm(phi, axis=1)
            spin = np.linalg.norm(phi_ddot, axis=1) + (_jacobian_rate(theta) + 1.0) * w2
        else:
            spin = np.full(times.shape, float(np.dot(b.angular_velocity, b.angular_velocity)))
        arm = max((float(np.linalg.norm(gl.point)) for gl in b.goals if gl.has_position), default=0)
        inertia = _inertia_bound(RandomScenarioConfig(shape=b.shape, size=b.size, mass=b.mass))
        force = b.mass * (np.linalg.norm(accel - g, axis=1) + arm * spin)
        out.append((float(force.max()), float(inertia * spin.max())))
    return out


def _jacobian_rate(theta: np.ndarray) -> np.ndarray:
    """``(theta e^theta - e^theta + 1) / theta^2``, its series ``1/2 + theta/3 + theta^2/8``
    below 1e-3."""
    small = theta < 1e-3
    t = np.where(small, 1.0, theta)
    exact = (t * np.exp(t) - np.exp(t) + 1.0) / (t * t)
    return np.where(small, 0.5 + theta / 3.0 + theta * theta / 8.0, exact)
