"""Random three-rod scenes: the paper's demo (``sgc_env.scenes.three_rods``) with its paths, red
balls and target times drawn from the env's ``np_random`` on every reset.

Each rod's path is the cubic spline through the paper's waypoints moved by drawn offsets
(the hit point stays on the target face); the goal counts before and after the ball, the
pierce and hit times, the balls' velocities and where the teal rod turns its somersault are
drawn too. Rods, balls and the target board keep their geometry, so the observation and action
spaces are those of ``SGCThreeRods-v2`` for every draw; the limits are constants of the id
(twice the paper scene's).

Feasibility: a rod is kept only if a planner-free bound of the force and torque its analytic
plan needs (``sgc_env.scenes.course_bound``, with this family's measured factors
``BOUND_FACTORS``) stays within ``demand_share`` of the limits; otherwise it is redrawn.
Planning every draw (v1) made a reset cost ~170 ms; the bound costs a fraction of a
millisecond, and each rod is built straight into model objects (``_rod_scene``) instead of
YAML-ready data that is parsed and resolved (``docs/environments.md`` has the figures).
A draw is issue 19's 10 ms budget: its orientation courses are memoised for the env's tracks
(``sgc_env.scenario.orientation_courses``), its small-vector arithmetic is plain floats and
its routing skips the checks a drawn rod passes by construction (``_route``), all giving the
floats they replaced, bit for bit.
``tests/sgc_env/scenes/test_random_scenes.py`` checks the bound against the planner on fresh draws
and runs the expert inside PyBullet on the draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from sgc_env.paper import quaternion as quat
from sgc_env.paper.routing import cumulative_fractions
from sgc_env.scenario import Body, Goal, Prop, Scenario, scenario_from_dict
from sgc_env.scenario.demand import inertia_diagonal
from sgc_env.scenario.model import Vec3, grid_time
from sgc_env.scenes.course_bound import (
    body_bound,
    course_features,
    demand_bound,
    point_feature,
    spin_feature,
)
from sgc_env.scenes.three_rods import (
    BALL_COLOR,
    BALL_RADIUS,
    EMBED_DURATION,
    FORCE_LIMIT,
    MARGIN,
    ROD_LENGTH,
    ROD_MASS,
    ROD_RADIUS,
    ROD_SPECS,
    TARGET_CENTER,
    TARGET_FACE_X,
    TARGET_HALF_EXTENTS,
    TIP,
    TORQUE_LIMIT,
    RodPath,
    RodSpec,
    ball_name,
    build_three_rods,
    rod_path,
)

__all__ = [
    "BOUND_FACTORS", "RandomThreeRodsConfig", "draw_rod", "random_three_rods", "rod_bound",
]  # fmt: skip

MAX_DRAWS = 1000
SOMERSAULT_ROD = 1
"""Index in ``ROD_SPECS`` of the rod that turns the somersault (the teal one, as in the paper)."""
ROD_INERTIA = float(inertia_diagonal("rod", (ROD_LENGTH, ROD_RADIUS), ROD_MASS).max())
FINE_POINTS = 401
"""Points per arc-length measurement of a drawn path (the paper's scene uses 2001; the goals
move by well under a millimetre)."""
FACTOR_MARGIN = 1.25
"""On top of the measured factors; ``demand_share`` leaves another 1.25 before the limits."""
MEASURED_FACTORS = ((1.49, 2.00), (2.57, 4.12), (3.16, 3.12))
"""Per rod of ``ROD_SPECS``, the largest ``(K_F, K_S)`` of ``sgc_env.scenes.course_bound``
measured on its draws: ``scripts/fit_course_bound.py --rods 400 --seed 200``, ``--rods 200
--seed 100`` and ``--rods 150 --seed 300`` (the violet rod's 3.12), and 200 more draws per rod
of an exploratory run (the teal rod's 2.57 and 4.12: one draw; its others stayed below 1.37
and 1.8). The largest values grew with the number of draws (violet's K_S: 2.44, 2.70, 3.12),
hence the margin."""
BOUND_FACTORS = tuple((FACTOR_MARGIN * f, FACTOR_MARGIN * s) for f, s in MEASURED_FACTORS)
"""What the draws use: the measured factors with a margin
(``tests/sgc_env/scenes/test_random_scenes.py`` checks the bound against the planner on fresh
draws)."""


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
    """``base`` with drawn waypoints, goal counts, times and ball velocity (no somersault).
    The draws' order is the family's definition; the clamps and the ball's direction are
    plain floats (the same values as on the arrays, at a fraction of numpy's per-call cost)."""
    points = _waypoints(base)
    moved = (points + rng.uniform(-cfg.waypoint_spread, cfg.waypoint_spread, points.shape)).tolist()
    moved[0] = (points[0] + rng.uniform(-cfg.start_spread, cfg.start_spread, 3)).tolist()
    hy, hz = TARGET_HALF_EXTENTS[1] - 0.5, TARGET_HALF_EXTENTS[2] - 0.5
    _, y, z = (points[-1] + rng.uniform(-cfg.hit_spread, cfg.hit_spread, 3)).tolist()
    y = min(max(y, TARGET_CENTER[1] - hy), TARGET_CENTER[1] + hy)
    z = min(max(z, TARGET_CENTER[2] - hz), TARGET_CENTER[2] + hz)
    moved[-1] = [TARGET_FACE_X, y, z]
    moved[-2][0] = min(moved[-2][0], TARGET_FACE_X - 2.0)
    f = cfg.control_frequency
    direction = rng.normal(size=3)
    after = base.samples_after + int(
        rng.integers(-cfg.samples_after_change, cfg.samples_after_change + 1)
    )
    samples_before = int(rng.integers(cfg.samples_before[0], cfg.samples_before[1] + 1))
    hit_time = grid_time(base.hit_time + rng.uniform(-1, 1) * cfg.hit_time_change, f)
    pierce_time = grid_time(rng.uniform(*cfg.pierce_time), f)
    norm, speed = float(np.linalg.norm(direction)), rng.uniform(*cfg.ball_speed)
    return replace(
        base,
        waypoints=tuple(map(tuple, moved)),
        samples_before=samples_before,
        samples_after=after,
        hit_time=hit_time,
        pierce_time=pierce_time,
        ball_velocity=tuple(c / norm * speed for c in direction.tolist()),
        somersault_sample=None,
    )


@lru_cache(maxsize=len(ROD_SPECS))
def _waypoints(base: RodSpec) -> np.ndarray:
    """A paper rod's waypoints as an array, made once (the draws only read it)."""
    points = np.asarray(base.waypoints, float)
    points.flags.writeable = False
    return points


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
    template = _template()
    return replace(
        template, bodies=tuple(body for body, _ in rods),
        props=(*(ball for _, ball in rods), template.props[-1]),
        control_frequency=cfg.control_frequency, resolved=True,
    )  # fmt: skip


def _feasible_rod(
    rng: np.random.Generator, k: int, cfg: RandomThreeRodsConfig
) -> tuple[Body, Prop]:
    """Rod ``k``'s body and ball, drawn until within the limits; model objects are built
    only for the rod kept."""
    share = cfg.demand_share
    for _ in range(MAX_DRAWS):
        candidate = _candidate(rng, k, cfg)
        bound = None if candidate is None else _candidate_bound(candidate, k)
        if bound is None or candidate is None:
            continue
        if bound[0] <= share * cfg.force_limit and bound[1] <= share * cfg.torque_limit:
            return _rod_body(candidate, cfg), candidate.ball
    raise RuntimeError(
        f"no feasible {ROD_SPECS[k].name} in {MAX_DRAWS} draws: narrow the ranges or raise "
        "the limits"
    )


def rod_bound(scenario: Scenario, k: int) -> tuple[float, float] | None:
    """The course bound of the force and torque the plan of rod ``k``'s scene needs, or None
    where its course data admit none (``sgc_env.scenes.course_bound``; the draws compute the
    same floats from the rod's arrays before building its scene, tested)."""
    body = scenario.bodies[0]
    features = course_features(body, scenario.control_frequency)
    if features is None:
        return None
    return body_bound(body, features, BOUND_FACTORS[k], float(np.linalg.norm(scenario.gravity)))


def draw_rod(rng: np.random.Generator, k: int, cfg: RandomThreeRodsConfig) -> Scenario | None:
    """One resolved scene of rod ``k`` alone, not yet checked against the limits; None where
    its tip would not enter the board steeply enough or two routed goal times share a tick."""
    candidate = _candidate(rng, k, cfg)
    return None if candidate is None else _rod_scene(candidate, cfg)


@dataclass(frozen=True)
class _Candidate:
    """A drawn rod's path with its goal times and ball, before any model object exists."""

    path: RodPath
    ball: Prop
    nails: np.ndarray
    tip: tuple[float, float, float]
    """Where the tip starts, as ``course_features`` computes it from the built body."""
    times: list[float]
    fixed: frozenset[int]
    weights: list[float]
    somersault: int | None
    frequency: int


def _candidate(rng: np.random.Generator, k: int, cfg: RandomThreeRodsConfig) -> _Candidate | None:
    """Draw rod ``k``'s path and route its goal times as ``resolve_scenario`` does."""
    spec = _rod_spec(rng, ROD_SPECS[k], cfg)
    if k == SOMERSAULT_ROD:
        spec = _with_somersault(rng, spec)
    return _candidate_of(spec, cfg)


def _candidate_of(
    spec: RodSpec, cfg: RandomThreeRodsConfig, fine: int = FINE_POINTS
) -> _Candidate | None:
    path = rod_path(spec, fine=fine)
    if not _enters_board(path.nails[-2:], cfg.min_entry_cosine):
        return None
    f = cfg.control_frequency
    ball = Prop(
        name=ball_name(spec), shape="sphere", size=(BALL_RADIUS,), color=BALL_COLOR,
        position=_vec3(path.ball_position), velocity=spec.ball_velocity,
    )  # fmt: skip
    n = len(path.orientations)
    hit = spec.hit_time
    fixed = {path.pierce: spec.pierce_time, n - 2: hit, n - 1: hit + EMBED_DURATION}
    nails = path.nails.copy()
    nails[path.pierce] = ball.position_at(spec.pierce_time)
    tip = _tip(path)
    # |nail_j - nail_{j-1}| in plain floats (numpy's norm sums the squares in this order)
    rows = [tip, *nails.tolist()]
    distances = [
        math.sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay) + (bz - az) * (bz - az))
        for (ax, ay, az), (bx, by, bz) in zip(rows[:-1], rows[1:], strict=True)
    ]
    somersault = spec.somersault_sample if path.turn is not None else None
    weights = [spec.somersault_weight if j == somersault else 1.0 for j in range(n)]
    anchors = [(j, grid_time(fixed[j], f)) for j in sorted(fixed)]
    times = [grid_time(t, f) for t in _route(distances, weights, anchors)]
    if any(b <= a for a, b in zip([0.0, *times], times, strict=False)):
        return None
    return _Candidate(path, ball, nails, tip, times, frozenset(fixed), weights, somersault, f)


def _route(
    distances: list[float], weights: list[float], anchors: list[tuple[int, float]]
) -> list[float]:
    """``resolve_goal_times`` of goals whose time-critical ones are ``anchors`` (index, time;
    increasing, the last goal last): its arithmetic without its per-goal checks, which cost
    as much as the rest of the routing and which a drawn rod passes by construction (its
    course lengths are positive; the times are checked on the grid afterwards)."""
    out: list[float] = []
    first, t0 = 0, 0.0
    for last, t in anchors:
        if last > first:
            share = np.divide(distances[first : last + 1], weights[first : last + 1])
            out += (t0 + (t - t0) * cumulative_fractions(share))[:-1].tolist()
        out.append(t)
        first, t0 = last + 1, t
    return out


def _tip(path: RodPath) -> tuple[float, float, float]:
    """The tip's start, as ``course_features`` computes it from the built body."""
    (x, y, z), (dx, dy, dz) = _vec3(path.com_start), quat.rotate(path.start, TIP)
    return x + dx, y + dy, z + dz


def _orientation_goals(c: _Candidate) -> list[tuple[quat.Quat | None, Vec3 | None]]:
    turn = None if c.path.turn is None else _vec3(c.path.turn)
    return [
        (None, turn) if j == c.somersault else (q, None) for j, q in enumerate(c.path.orientations)
    ]


def _candidate_bound(c: _Candidate, k: int) -> tuple[float, float] | None:
    """:func:`rod_bound` of the rod's scene, from its arrays (the same floats)."""
    rest = _REST
    spin = spin_feature(c.path.start, _orientation_goals(c), c.times, (rest, rest), c.frequency)
    if spin is None:
        return None
    point = point_feature(c.times, np.asarray(c.tip), c.nails, c.path.launch, rest)
    return demand_bound(
        (point, spin), BOUND_FACTORS[k], mass=ROD_MASS, inertia=ROD_INERTIA, arm=TIP_ARM,
        gravity=_gravity(),
    )  # fmt: skip


_REST = np.zeros(3)
_REST.flags.writeable = False
TIP_ARM = float(np.linalg.norm(TIP))
"""The tracked point's distance from the centre of mass (``body_bound``'s ``arm``)."""


@lru_cache(maxsize=1)
def _gravity() -> float:
    return float(np.linalg.norm(_template().gravity))


def _rod_scene(c: _Candidate, cfg: RandomThreeRodsConfig) -> Scenario:
    """The rod's resolved scene built straight from its path: what ``rod_entries``, the parser
    and ``resolve_scenario`` make of it up to their 12-digit rounding (tested), at a fraction
    of their cost (the field checks and dict round trips were half of a draw)."""
    template = _template()
    return replace(
        template, bodies=(_rod_body(c, cfg),), props=(c.ball, template.props[-1]),
        control_frequency=c.frequency, resolved=True,
    )  # fmt: skip


def _rod_body(c: _Candidate, cfg: RandomThreeRodsConfig) -> Body:
    """The body of :func:`_rod_scene` (the draws assemble one scene of the three)."""
    spec, rows = c.path.spec, c.nails.tolist()
    goals = tuple(
        Goal(
            nail=tuple(rows[j]),
            point=TIP,
            orientation=orientation,
            relative_rotation=relative,
            time=c.times[j],
            critical=j in c.fixed,
            weight=c.weights[j],
            nail_prop=c.ball.name if j == c.path.pierce else None,
        )  # fmt: skip
        for j, (orientation, relative) in enumerate(_orientation_goals(c))
    )
    return Body(
        name=spec.name, shape="rod", size=(ROD_LENGTH, ROD_RADIUS), mass=ROD_MASS,
        position=_vec3(c.path.com_start), orientation=c.path.start,
        linear_velocity=_vec3(c.path.launch), color=spec.color,
        force_limit=float(cfg.force_limit), torque_limit=float(cfg.torque_limit), goals=goals,
        end_velocity=(0.0, 0.0, 0.0), end_angular_velocity=(0.0, 0.0, 0.0), collisions=False,
    )  # fmt: skip


@lru_cache(maxsize=1)
def _template() -> Scenario:
    """The paper's gold rod alone, parsed once: the draws reuse its scene fields and target."""
    return scenario_from_dict(build_three_rods(ROD_SPECS[:1], name="three_rods_random"))


def _enters_board(hit_and_embed: np.ndarray, min_cosine: float) -> bool:
    """The rod's last course (the embed) heads into the board steeply enough."""
    step = hit_and_embed[1] - hit_and_embed[0]
    return bool(step[0] / np.linalg.norm(step) >= min_cosine)
