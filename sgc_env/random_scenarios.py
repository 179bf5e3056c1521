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

import numpy as np

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


PRESETS: dict[str, RandomScenarioConfig] = {
    "point": RandomScenarioConfig(),
    "rod": RandomScenarioConfig(shape="rod", size=(0.6, 0.03), orientation=True),
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


def random_scenario(
    rng: np.random.Generator, config: RandomScenarioConfig | str = "point"
) -> Scenario:
    """Draw one resolved, feasible single-body scenario from ``rng``."""
    cfg = PRESETS[config] if isinstance(config, str) else config
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
        workspace=(tuple(start - hw), tuple(start + hw)),  # type: ignore[arg-type]
        margin=cfg.margin,
        control_frequency=f,
    )
    return resolve_scenario(scenario)


def planner_demand(scenario: Scenario, samples: int = 120) -> list[tuple[float, float]]:
    """Peak |force| and |torque| per body along the analytic SGC plan (``sgc_env.paper.plan``).

    Force = m (a - g); torque bounded by I_max |alpha| + I_max |omega|^2 (gyroscopic term). The
    torque action ``R0 diag(1 / torque_scale) R0^T tau`` has principal components
    (I_k alpha_k + gyro_k) / (torque_limit I_k / I_max), and |gyro_k| <= I_k |omega_j omega_l|
    (principal moments obey I_k >= |I_j - I_l|), so its norm, and every entry, stays below
    (I_max |alpha| + I_max |omega|^2) / torque_limit: the same bound below ``torque_limit``
    keeps the scaled torque action inside the box.
    Costly (milliseconds), so the env does not call it on every reset; tests use it to show
    that the limits from the geometric bound cover what the plan needs.
    """
    from sgc_env.paper.plan import BodyState, OrientationGoal, PositionGoal, plan_body

    g = np.asarray(scenario.gravity, float)
    out = []
    for b in scenario.bodies:
        plan = plan_body(
            BodyState(
                np.asarray(b.position), np.asarray(b.orientation),
                np.asarray(b.linear_velocity), np.asarray(b.angular_velocity),
            ),
            [PositionGoal(gl.time, np.asarray(gl.nail), np.asarray(gl.point))
             for gl in b.goals if gl.has_position],
            [OrientationGoal(gl.time, orientation=None if gl.orientation is None
                             else np.asarray(gl.orientation),
                             relative_rotation=None if gl.relative_rotation is None
                             else np.asarray(gl.relative_rotation))
             for gl in b.goals if gl.has_orientation],
        )  # fmt: skip
        inertia = _inertia_bound(RandomScenarioConfig(shape=b.shape, size=b.size, mass=b.mass))
        t_end = max(float(gl.time) for gl in b.goals)  # type: ignore[arg-type]
        force = torque = 0.0
        for t in np.linspace(0.0, t_end, samples):
            smp = plan.sample(float(t))
            force = max(force, b.mass * float(np.linalg.norm(smp.acceleration - g)))
            w = float(np.linalg.norm(smp.angular_velocity))
            alpha = float(np.linalg.norm(smp.angular_acceleration))
            torque = max(torque, inertia * (alpha + w * w))
        out.append((force, torque))
    return out
