"""Where the batched env's step time goes, against SB3's DummyVecEnv, for ids at N sub-envs.

For each id, both kinds run the same hover-plus-noise actions as ``bench_vec.py`` (episodes
that end are reset inside the step, as there). Per tick (one step of all N sub-envs), in ms:
the whole step, the sub-env resets in it and the random scene draws in those resets (timers
around ``SGCEnv.reset`` and the scene family's ``draw``). Then PyBullet's own calls of one
batched tick, replayed alone on the batch's bodies (force and torque on every body each
substep, ``stepSimulation`` of every world, the two reads per body: what the batched env
cannot do without), and three ratios to DummyVecEnv: measured; with scene draws free in both
kinds (the draw is the same code in both); and a batched env that cost nothing but PyBullet's
calls and its draws. Each figure is the best of ``--repeats`` passes; run it on a quiet core.

    taskset -c 0 .venv/bin/python scripts/bench_vec_split.py --ids SGCThreeRodsRandom-v3 \
        SGCThreeRodsRandom-v3 SGCRod-v1
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from itertools import chain
from typing import Any

import gymnasium as gym
import numpy as np

import sgc_env
from baselines.agents.sb3_vec_env import make_sgc_vec
from baselines.timing.bare import hover_action
from sgc_env.envs.sgc_env import SGCEnv
from sgc_env.envs.vector.batch import check_num_envs
from sgc_env.scenes import family
from sgc_env.simulator import pybullet as pb

TIMERS = ("reset", "draw")


class Timers:
    """Seconds spent in ``SGCEnv.reset`` and in the id's scene draw, and their calls, while
    installed."""

    def __init__(self, env_id: str) -> None:
        self.spent = dict.fromkeys(TIMERS, 0.0)
        self.calls = dict.fromkeys(TIMERS, 0)
        preset = gym.spec(env_id).kwargs.get("random_scenario")
        self._targets: list[tuple[Any, str]] = [(SGCEnv, "reset")]
        if preset is not None:
            self._targets.append((type(family(preset)), "draw"))
        self._originals: list[tuple[Any, str, Callable[..., Any]]] = []

    def _timed(self, key: str, method: Callable[..., Any]) -> Callable[..., Any]:
        spent, calls = self.spent, self.calls

        def timed(*args: Any, **kwargs: Any) -> Any:
            started = time.perf_counter()
            try:
                return method(*args, **kwargs)
            finally:
                spent[key] += time.perf_counter() - started
                calls[key] += 1

        return timed

    def __enter__(self) -> Timers:
        for owner, name in self._targets:
            original = owner.__dict__[name]
            self._originals.append((owner, name, original))
            setattr(owner, name, self._timed(name, original))
        return self

    def __exit__(self, *exc: object) -> None:
        for owner, name, original in self._originals:
            setattr(owner, name, original)
        self._originals.clear()


def tick_split(env_id: str, n: int, kind: str, ticks: int) -> tuple[dict[str, float], Any]:
    """ms per tick of the step, its resets and its draws, and resets per tick, for one kind;
    and the env (open)."""
    env = make_sgc_vec(env_id, n, seed=0, vec=kind)
    env.reset()
    first = env.get_attr("unwrapped", [0])[0]
    rng = np.random.default_rng(0)
    actions = hover_action(first) + rng.normal(0.0, 0.1, (ticks + 5, n, *first.action_space.shape))
    actions = actions.astype(np.float32)
    for t in range(5):
        env.step(actions[t])
    with Timers(env_id) as timers:
        started = time.perf_counter()
        for t in range(ticks):
            env.step(actions[5 + t])
        total = time.perf_counter() - started
    out = {"total": total, **timers.spent}
    split = {key: value / ticks * 1e3 for key, value in out.items()}
    split["resets_per_tick"] = timers.calls["reset"] / ticks
    return split, env


def physics_floor(subs: list[SGCEnv], ticks: int) -> tuple[float, int, int]:
    """ms per tick of PyBullet's calls alone for these sub-envs' bodies (as the batched env
    makes them: every body's drives on each substep, each world stepped, two reads per body),
    the number of bodies and of worlds."""
    handles = [(s.sim.bodies[b.name].uid, s.sim.client) for s in subs for b in s.scenario.bodies]
    uids, clients = [u for u, _ in handles], [c for _, c in handles]
    worlds = sorted(set(clients))
    count, substeps, torque = len(uids), subs[0].substeps, subs[0].use_torque
    minus, frame = [-1] * count, [pb.WORLD_FRAME] * count
    force, at = [[0.0, 0.0, 1.0]] * count, [[0.0, 0.0, 0.0]] * count
    flat = chain.from_iterable
    started = time.perf_counter()
    for _ in range(ticks):
        for _ in range(substeps):
            for _ in map(pb.applyExternalForce, uids, minus, force, at, frame, clients):
                pass
            if torque:
                for _ in map(pb.applyExternalTorque, uids, minus, force, frame, clients):
                    pass
            for c in worlds:
                pb.stepSimulation(c)
        poses = flat(flat(map(pb.getBasePositionAndOrientation, uids, clients)))
        speeds = flat(flat(map(pb.getBaseVelocity, uids, clients)))
        np.fromiter(poses, np.float64, 7 * count)
        np.fromiter(speeds, np.float64, 6 * count)
    return (time.perf_counter() - started) / ticks * 1e3, count, len(worlds)


def report(env_id: str, n: int, ticks: int, repeats: int) -> None:
    best: dict[str, dict[str, float]] = {}
    floor = float("inf")
    for _ in range(repeats):
        for kind in ("batched", "dummy"):
            split, env = tick_split(env_id, n, kind, ticks)
            old = best.setdefault(kind, split)
            if split["total"] < old["total"]:
                best[kind] = split
            if kind == "batched":
                ms, bodies, worlds = physics_floor(env.get_attr("unwrapped"), ticks)
                floor = min(floor, ms)
            env.close()
    b, d = best["batched"], best["dummy"]
    print(f"{env_id}, N = {n}, ms per tick (best of {repeats} passes of {ticks} ticks)")
    print(f"  {'kind':8} {'step':>7} {'resets':>7} {'draws':>7} {'rest':>7} {'resets/tick':>11}")
    for kind, s in best.items():
        rest = s["total"] - s["reset"]
        print(
            f"  {kind:8} {s['total']:7.3f} {s['reset']:7.3f} {s['draw']:7.3f} {rest:7.3f} "
            f"{s['resets_per_tick']:11.2f}"
        )
    print(f"  PyBullet's calls alone ({bodies} bodies, {worlds} worlds): {floor:.3f}")
    print(f"  x dummy, measured:                          {d['total'] / b['total']:5.2f}")
    free = (d["total"] - d["draw"]) / (b["total"] - b["draw"])
    print(f"  x dummy, draws free in both:                {free:5.2f}")
    print(f"  x dummy, batched = PyBullet's calls + draws: {d['total'] / (floor + b['draw']):5.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--ids", nargs="+", default=["SGCThreeRodsRandom-v3", "SGCThreeRodsRandom-v3"]
    )
    parser.add_argument("--n", type=int, default=64)
    parser.add_argument("--ticks", type=int, default=320, help="steps of all N sub-envs timed")
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    for name in ("ticks", "repeats"):
        if getattr(args, name) < 1:
            parser.error(f"--{name}: expected an int >= 1, got {getattr(args, name)}")
    try:
        check_num_envs(args.n)
    except ValueError as err:
        parser.error(f"--n: {err}")
    ids = sgc_env.ENV_IDS
    for env_id in args.ids:
        if env_id not in ids:
            parser.error(f"--ids: {env_id!r} is not an SGC id; ids: {list(ids)}")
        report(env_id, args.n, args.ticks, args.repeats)


if __name__ == "__main__":
    main()
