"""Random three-rod scenes: the paper's demo (``sgc_env.scenes.three_rods``) with its paths, red
balls and target times drawn from the env's ``np_random`` on every reset.

Each rod's path is the cubic spline through the paper's waypoints moved by drawn offsets
(the hit point stays on the target face); the goal counts before and after the ball, the
pierce and hit times, the balls' velocities and where the teal rod turns its somersault are
drawn too. Rods, balls and the target board keep their geometry, so the observation and action
spaces are those of ``SGCThreeRods-v1`` for every draw; the limits are constants of the id
(twice the paper scene's).

Feasibility: a rod is kept only if bounds of the force and torque along its analytic plan
(``demand_bounds``) stay within ``demand_share`` of the limits; otherwise it is redrawn.
Planning the rods costs far more than a reset of a fixed scene (``docs/environments.md`` has
the figures).
``tests/test_random_scenes.py`` runs the expert inside PyBullet on the draws.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np

from sgc_env.scenario import Body, Goal, Prop, Scenario, resolve_scenario, scenario_from_dict
from sgc_env.scenario.demand import demand_bounds
from sgc_env.scenario.model import grid_time
from sgc_env.scenes.three_rods import (
    EMBED_DURATION,
    FORCE_LIMIT,
    MARGIN,
    ROD_MASS,
    ROD_SPECS,
    TARGET_CENTER,
    TARGET_FACE_X,
    TARGET_HALF_EXTENTS,
    TORQUE_LIMIT,
    RodSpec,
    build_three_rods,
    rod_entries,
)

__all__ = ["RandomThreeRodsConfig", "random_three_rods"]

MAX_DRAWS = 1000
SOMERSAULT_ROD = 1
"""Index in ``ROD_SPECS`` of the rod that turns the somersault (the teal one, as in the paper)."""


@dataclass(frozen=True)
class RandomThreeRodsConfig:
    """Ranges of the three-rod family around the paper's scene (``ROD_SPECS``)."""

    start_spread: float = 0.3
    waypoint_spread: float = 0.4
    hit_spread: float = 0.6
    samples_before: tuple[int, int] = (2, 4)
    samples_after_change: int = 2
    pierce_time: tuple[float, float] = (1.0, 1.4)
    hit_time_change: float = 0.4
    ball_speed: tuple[float, float] = (0.5, 1.2)
    min_entry_cosine: float = 0.5
    """The tip must enter the board within 60 degrees of its normal (the embed goal is
    ``EMBED_DEPTH`` into the board along the path's end tangent)."""
    force_limit: float = 2 * FORCE_LIMIT
    torque_limit: float = 2 * TORQUE_LIMIT
    """Twice the paper scene's limits: drawn paths bend and speed up more than the paper's
    hand-placed ones (constants, so the action scale is the same in every episode)."""
    demand_share: float = 0.8
    """Largest share of each limit the plan's force and torque bounds may use: the expert's
    per-tick wrench can exceed the continuous plan's peak by a few percent."""
    control_frequency: int = 60

    def __post_init__(self) -> None:
        lo, hi = self.samples_before
        if not 1 <= lo <= hi:
            raise ValueError(f"samples_before: expected 1 <= low <= high, got {(lo, hi)}")
        if not 0 < self.pierce_time[0] <= self.pierce_time[1]:
            raise ValueError(f"pierce_time: expected 0 < low <= high, got {self.pierce_time}")
        if not 0 <= self.samples_after_change < min(s.samples_after for s in ROD_SPECS):
            raise ValueError(
                f"samples_after_change: expected 0 <= change < every rod's samples_after, got "
                f"{self.samples_after_change}"
            )
        if not 0 < self.demand_share <= 1:
            raise ValueError(f"demand_share: expected (0, 1], got {self.demand_share}")
        if self.force_limit <= ROD_MASS * 9.81 or self.torque_limit <= 0:
            raise ValueError(
                f"force_limit {self.force_limit} N must exceed the rod's weight and "
                f"torque_limit {self.torque_limit} N m must be positive"
            )

    def draw(self, rng: np.random.Generator) -> Scenario:
        return random_three_rods(rng, self)

    def goal_counts(self) -> tuple[tuple[int, int], ...]:
        """Fewest and most goals per rod (samples before and after the ball, and the embed)."""
        lo, hi = self.samples_before
        change = self.samples_after_change
        return tuple(
            (lo + s.samples_after - change + 1, hi + s.samples_after + change + 1)
            for s in ROD_SPECS
        )

    def max_steps(self) -> int:
        """Each rod's last goal is its embed, ``EMBED_DURATION`` after a hit time drawn within
        ``hit_time_change`` of the paper's; the margin is the builder's."""
        f = self.control_frequency
        last = max(spec.hit_time for spec in ROD_SPECS) + self.hit_time_change + EMBED_DURATION
        return math.ceil(last * f) + 1 + math.ceil(MARGIN * f - 1e-9)


def _vec3(v: np.ndarray) -> tuple[float, float, float]:
    x, y, z = (float(c) for c in v)
    return x, y, z


def _rod_spec(rng: np.random.Generator, base: RodSpec, cfg: RandomThreeRodsConfig) -> RodSpec:
    """``base`` with drawn waypoints, goal counts, times and ball velocity (no somersault)."""
    points = np.asarray(base.waypoints, float)
    moved = points + rng.uniform(-cfg.waypoint_spread, cfg.waypoint_spread, points.shape)
    moved[0] = points[0] + rng.uniform(-cfg.start_spread, cfg.start_spread, 3)
    hy, hz = TARGET_HALF_EXTENTS[1] - 0.5, TARGET_HALF_EXTENTS[2] - 0.5
    hit = points[-1] + rng.uniform(-cfg.hit_spread, cfg.hit_spread, 3)
    hit[0] = TARGET_FACE_X
    hit[1] = np.clip(hit[1], TARGET_CENTER[1] - hy, TARGET_CENTER[1] + hy)
    hit[2] = np.clip(hit[2], TARGET_CENTER[2] - hz, TARGET_CENTER[2] + hz)
    moved[-1] = hit
    moved[-2][0] = min(moved[-2][0], TARGET_FACE_X - 2.0)
    f = cfg.control_frequency
    direction = rng.normal(size=3)
    after = base.samples_after + int(
        rng.integers(-cfg.samples_after_change, cfg.samples_after_change + 1)
    )
    return replace(
        base,
        waypoints=tuple(_vec3(p) for p in moved),
        samples_before=int(rng.integers(cfg.samples_before[0], cfg.samples_before[1] + 1)),
        samples_after=after,
        hit_time=grid_time(base.hit_time + rng.uniform(-1, 1) * cfg.hit_time_change, f),
        pierce_time=grid_time(rng.uniform(*cfg.pierce_time), f),
        ball_velocity=_vec3(direction / np.linalg.norm(direction) * rng.uniform(*cfg.ball_speed)),
        somersault_sample=None,
    )


def _with_somersault(rng: np.random.Generator, spec: RodSpec) -> RodSpec:
    """The somersault in the middle third of the path after the ball, as in the paper."""
    first = spec.samples_before + spec.samples_after // 3
    sample = int(rng.integers(first, first + max(1, spec.samples_after // 3)))
    return replace(spec, somersault_sample=sample)


def random_three_rods(
    rng: np.random.Generator, config: RandomThreeRodsConfig | None = None
) -> Scenario:
    """Draw one resolved, feasible three-rod scene from ``rng``.

    The rods do not interact, so each is drawn on its own until it is feasible (a rejected
    gold rod does not cost the teal and violet ones their plans)."""
    cfg = config or RandomThreeRodsConfig()
    rods = [_feasible_rod(rng, k, cfg) for k in range(len(ROD_SPECS))]
    target = rods[0].props[-1]
    return replace(
        rods[0],
        name="three_rods_random",
        bodies=tuple(r.bodies[0] for r in rods),
        props=(*(r.props[0] for r in rods), target),
    )


def _feasible_rod(rng: np.random.Generator, k: int, cfg: RandomThreeRodsConfig) -> Scenario:
    """A resolved scene of rod ``k`` alone (with its ball and the target) within the limits."""
    share = cfg.demand_share
    for _ in range(MAX_DRAWS):
        spec = _rod_spec(rng, ROD_SPECS[k], cfg)
        if k == SOMERSAULT_ROD:
            spec = _with_somersault(rng, spec)
        body, ball = rod_entries(spec)
        if not _enters_board(body, cfg.min_entry_cosine):
            continue
        # Built straight into model objects and resolved without the field checks: the
        # entries are valid by construction (tests compare with the YAML route).
        scenario = resolve_scenario(
            replace(
                _template(),
                bodies=(_body(body, cfg),),
                props=(_prop(ball), _template().props[-1]),
                control_frequency=cfg.control_frequency,
            ),
            check_plan=False,
            validate=False,
        )
        ((force, torque),) = demand_bounds(scenario)
        if force <= share * cfg.force_limit and torque <= share * cfg.torque_limit:
            return scenario
    raise RuntimeError(
        f"no feasible {ROD_SPECS[k].name} in {MAX_DRAWS} draws: narrow the ranges or raise "
        "the limits"
    )


@lru_cache(maxsize=1)
def _template() -> Scenario:
    """The paper's gold rod alone, parsed once: the draws reuse its scene fields and target."""
    return scenario_from_dict(build_three_rods(ROD_SPECS[:1], name="three_rods_random"))


def _floats(values: Sequence[float]) -> tuple[float, ...]:
    return tuple(float(x) for x in values)


def _unit(q: Sequence[float]) -> tuple[float, ...]:
    """Normalised as the parser normalises a quaternion (the same floats)."""
    norm = math.sqrt(sum(x * x for x in q))
    return tuple(x / norm for x in q)


def _goal(g: dict[str, Any]) -> Goal:
    nail = g["nail"]
    prop = isinstance(nail, dict)
    rotation = g.get("relative_rotation")
    return Goal(
        nail=None if prop else _floats(nail),  # type: ignore[arg-type]
        nail_prop=nail["prop"] if prop else None,
        point=_floats(g["point"]),  # type: ignore[arg-type]
        orientation=_unit(g["orientation"]) if "orientation" in g else None,  # type: ignore[arg-type]
        relative_rotation=None if rotation is None else _floats(rotation),  # type: ignore[arg-type]
        time=float(g["time"]) if "time" in g else None,
        weight=float(g.get("weight", 1.0)),
    )


def _body(d: dict[str, Any], cfg: RandomThreeRodsConfig) -> Body:
    """A ``rod_entries`` body as ``scenario_from_dict`` would parse it, with the id's limits."""
    return Body(
        name=d["name"],
        shape=d["shape"],
        size=_floats(d["size"]),
        mass=float(d["mass"]),
        position=_floats(d["position"]),  # type: ignore[arg-type]
        orientation=_unit(d["orientation"]),  # type: ignore[arg-type]
        linear_velocity=_floats(d["linear_velocity"]),  # type: ignore[arg-type]
        color=_floats(d["color"]),  # type: ignore[arg-type]
        force_limit=float(cfg.force_limit),
        torque_limit=float(cfg.torque_limit),
        goals=tuple(_goal(g) for g in d["goals"]),
        end_velocity=_floats(d["end_velocity"]),  # type: ignore[arg-type]
        end_angular_velocity=_floats(d["end_angular_velocity"]),  # type: ignore[arg-type]
        collisions=bool(d["collisions"]),
    )


def _prop(d: dict[str, Any]) -> Prop:
    return Prop(
        name=d["name"],
        shape=d["shape"],
        size=_floats(d["size"]),
        color=_floats(d["color"]),  # type: ignore[arg-type]
        position=_floats(d["position"]),  # type: ignore[arg-type]
        velocity=_floats(d["velocity"]),  # type: ignore[arg-type]
        collisions=bool(d["collisions"]),
    )


def _enters_board(body: dict[str, Any], min_cosine: float) -> bool:
    """The rod's last course (the embed) heads into the board steeply enough."""
    hit, embed = (np.asarray(gl["nail"], float) for gl in body["goals"][-2:])
    step = embed - hit
    return bool(step[0] / np.linalg.norm(step) >= min_cosine)
