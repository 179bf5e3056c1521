"""Reset cost of the random ids, and of the random paper scenes against their fixed ids, measured
in the same run.

First, for every id registered with a random scene family: the mean ``env.reset(seed=...)``
time on the unwrapped env over ``--rounds`` rounds; the same in process CPU time (``cpu ms``:
what other jobs on a shared machine inflate least, and PyBullet DIRECT runs in this process);
the wall time's ratio to a bare PyBullet reset measured in the same run (one body of a DIRECT
client put back to its start pose and velocity); its share of stepping a full-length episode
(``% episode``); the redraw rate (``checks/scene``: feasibility checks per kept scene, and
``redraw %``: the share of checked draws rejected and drawn again; ``-`` for families whose
draw is feasible by construction and never checks); and whether the wall time (``yes``), only
the CPU time (``cpu``) or neither (``no``) stays within issue 19's 10 ms. Then, as before:

For SGCIntercept(Random)-v0 and SGCThreeRods-v2 / SGCThreeRodsRandom-v3: mean
``env.reset(seed=...)`` time on the unwrapped env, the ratio random / fixed, how many
feasibility checks (the planner's ``demand_bounds`` per drawn interception, the planner-free
course bound per drawn rod that enters the board) a kept scene took, and the mean time of one
check, and for scale the stepping time of a full-length episode of the random id (mean step
time under seeded random actions times the episode's steps). Then the CPU time per sub-env of
a reset of the batched env (8 sub-envs, each reset through the same ``SGCEnv.reset``). Last,
where the CPU time of the two random paper scenes' resets goes (``PHASES``; ``env``:
everything else: the env's own part, and for the rods drawing the specs).

    .venv/bin/python scripts/bench_random_scenes.py [--resets 20] [--rounds 3]
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the ids)
from sgc_env.envs.vector.vector_env import make_vec
from sgc_env.scenario import demand
from sgc_env.scenes import intercept, random_scenario, three_rods_random

TARGET_MS = 10.0
"""Issue 19's bound on a random id's reset (about a tenth of its episode's steps)."""
PAIRS = (("SGCIntercept-v1", "SGCInterceptRandom-v1", "intercept"),
         ("SGCThreeRods-v2", "SGCThreeRodsRandom-v3", "three_rods"))  # fmt: skip


def _bare_reset_ms(resets: int) -> float:
    """A bare PyBullet reset: one body of a DIRECT client put back to its start pose and
    velocity (the least any reset does)."""
    from sgc_env.simulator import pybullet as p

    client = p.connect(p.DIRECT)
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.05, physicsClientId=client)
    body = p.createMultiBody(1.0, shape, physicsClientId=client)
    start = time.perf_counter()
    for k in range(resets):
        p.resetBasePositionAndOrientation(body, (0, 0, k), (0, 0, 0, 1), physicsClientId=client)
        p.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0), physicsClientId=client)
    elapsed = time.perf_counter() - start
    p.disconnect(client)
    return elapsed / resets * 1e3


def _random_ids() -> list[tuple[str, str]]:
    """Every registered id with a random family, and the family's preset name."""
    out = []
    for env_id in sgc_env.ENV_IDS:
        preset = gym.spec(env_id).kwargs.get("random_scenario")
        if isinstance(preset, str):
            out.append((env_id, preset))
    return out


def _reset_ms(env_id: str, resets: int, rounds: int = 1) -> tuple[float, float]:
    """Mean ``reset(seed=...)`` ms over ``rounds`` rounds of ``resets`` seeds (the same seeds
    each round): wall-clock and process CPU time."""
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(rounds):
        for seed in range(1, resets + 1):
            env.reset(seed=seed)
    count = rounds * resets
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    env.close()
    return wall / count * 1e3, cpu / count * 1e3


def _episode_ms(env_id: str, steps: int) -> float:
    """Mean step time under seeded random actions (resets not timed) times the steps of a
    full-length episode (``max_steps`` of seed 0's scene)."""
    env = gym.make(env_id).unwrapped
    env.action_space.seed(0)
    env.reset(seed=0)
    length = env.max_steps
    elapsed, done = 0.0, False
    for _ in range(steps):
        if done:
            env.reset()
        start = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        elapsed += time.perf_counter() - start
        done = terminated or truncated
    env.close()
    return elapsed / steps * length * 1e3


def _draws_per_scene(family: str, scenes: int) -> tuple[float, float, float]:
    """Checks per kept scene, the mean ms of one check (0 checks: nan) and the share of
    checked draws redrawn (each check keeps a body or redraws it: the intercept checks its
    one body per scene, the three rods each rod on its own)."""
    calls, seconds, kept = [0], [0.0], 0
    checks = ((intercept, "demand_bounds"), (three_rods_random, "_candidate_bound"))
    saved = [getattr(module, name) for module, name in checks]

    def counted(check):
        def timed(*args, **kwargs):
            calls[0] += 1
            start = time.perf_counter()
            out = check(*args, **kwargs)
            seconds[0] += time.perf_counter() - start
            return out

        return timed

    for (module, name), check in zip(checks, saved, strict=True):
        setattr(module, name, counted(check))
    try:
        rng = np.random.default_rng(0)
        for _ in range(scenes):
            kept += len(random_scenario(rng, family).bodies)
    finally:
        for (module, name), check in zip(checks, saved, strict=True):
            setattr(module, name, check)
    if not calls[0]:
        return 0.0, float("nan"), float("nan")
    return calls[0] / scenes, seconds[0] / calls[0] * 1e3, 1.0 - kept / calls[0]


PHASES = (
    ("plan", demand, "body_plan"),
    ("bound", intercept, "demand_bounds"),
    ("bound", three_rods_random, "_candidate_bound"),
    ("build", three_rods_random, "rod_path"),
    ("resolve", intercept, "resolve_scenario"),
    ("resolve", three_rods_random, "_route"),
    ("resolve", three_rods_random, "_rod_body"),
)
"""Where a draw's CPU time goes: the planner, the feasibility bound (the intercept's sampling
of the plan, ``bound`` minus ``plan``; the rods' planner-free course bound), sampling the
rods' paths into goals, routing the goal times and building the scene's objects."""


def _batched_reset_ms(env_id: str, envs: int, rounds: int) -> float:
    """CPU ms per sub-env of ``reset(seed=...)`` on the batched env (``make_vec``: every
    sub-env in one PyBullet client, each reset through ``SubEnvs.reset_one``)."""
    vec = make_vec(env_id, num_envs=envs)
    vec.reset(seed=0)
    start = time.process_time()
    for r in range(1, rounds + 1):
        vec.reset(seed=1000 * r)
    elapsed = time.process_time() - start
    vec.close()
    return elapsed / (rounds * envs) * 1e3


@contextmanager
def _timed(seconds: dict[str, float]) -> Iterator[None]:
    """Add each phase's process CPU time to ``seconds`` while the block runs."""
    saved = [(module, name, getattr(module, name)) for _, module, name in PHASES]

    def timer(key: str, fn):
        def timed(*args, **kwargs):
            start = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                seconds[key] += time.process_time() - start

        return timed

    for (key, module, name), (_, _, fn) in zip(PHASES, saved, strict=True):
        setattr(module, name, timer(key, fn))
    try:
        yield
    finally:
        for module, name, fn in saved:
            setattr(module, name, fn)


def _split_ms(env_id: str, resets: int) -> dict[str, float]:
    """CPU ms per ``reset(seed=...)`` of each phase, and ``env`` for the rest of the reset."""
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    seconds: dict[str, float] = defaultdict(float)
    with _timed(seconds):
        start = time.process_time()
        for seed in range(1, resets + 1):
            env.reset(seed=seed)
        total = time.process_time() - start
    env.close()
    seconds["bound"] -= seconds["plan"]
    seconds["env"] = total - sum(seconds.values())
    return {key: value / resets * 1e3 for key, value in seconds.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resets", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3, help="rounds of the first table")
    args = parser.parse_args()
    bare = _bare_reset_ms(2000)
    print(f"bare PyBullet reset: {bare * 1e3:.1f} us")
    print(f"{'id':24s} {'reset ms':>9s} {'cpu ms':>8s} {'x bare':>8s} {'% episode':>9s}"
          f" {'checks/scene':>12s} {'redraw %':>8s} {'<= 10 ms':>9s}")  # fmt: skip
    for env_id, preset in _random_ids():
        ms, cpu = _reset_ms(env_id, args.resets, args.rounds)
        draws, _, redrawn = _draws_per_scene(preset, args.resets)
        rate = f"{draws:12.2f} {100 * redrawn:8.1f}" if draws else f"{'-':>12s} {'-':>8s}"
        verdict = "yes" if ms <= TARGET_MS else ("cpu" if cpu <= TARGET_MS else "no")
        share = 100 * ms / _episode_ms(env_id, 1000)
        print(f"{env_id:24s} {ms:9.2f} {cpu:8.2f} {ms / bare:8.0f} {share:9.1f} {rate}"
              f" {verdict:>9s}")  # fmt: skip
    print()
    print(f"{'id':24s} {'reset ms':>9s} {'x fixed':>8s} {'checks/scene':>12s} {'check ms':>9s}"
          f" {'episode ms':>11s}")  # fmt: skip
    for fixed, random_id, family in PAIRS:
        base, _ = _reset_ms(fixed, args.resets)
        drawn, _ = _reset_ms(random_id, args.resets)
        draws, check_ms, _ = _draws_per_scene(family, args.resets)
        episode = _episode_ms(random_id, 2000)
        print(f"{fixed:24s} {base:9.2f}")
        print(f"{random_id:24s} {drawn:9.2f} {drawn / base:8.0f} {draws:12.2f} {check_ms:9.2f}"
              f" {episode:11.1f}")  # fmt: skip
    print()
    print(f"{'batched, 8 sub-envs':24s} {'cpu ms per sub-env reset':>25s}")
    for env_id, _ in _random_ids():
        print(f"{env_id:24s} {_batched_reset_ms(env_id, 8, args.rounds):25.2f}")
    print()
    keys = ("plan", "bound", "build", "resolve", "env")
    print(f"{'CPU ms per reset':24s}" + "".join(f"{k:>9s}" for k in keys))
    for _, random_id, _ in PAIRS:
        split = _split_ms(random_id, args.resets)
        print(f"{random_id:24s}" + "".join(f"{split.get(k, 0.0):9.2f}" for k in keys))


if __name__ == "__main__":
    main()
