"""Env step cost of two checkouts in one process, interleaved: is a refactor's hot path as fast?

Imports ``sgc_env`` of ``--reference`` (another worktree, e.g. ``git worktree add /tmp/base
<commit>``), keeps its env class, then imports this checkout's ``sgc_env`` in its place. For
every registered id both envs run the same scenario under a hover action in alternating chunks
(``--rounds`` each, the order flipped every round). The best chunk per side is kept, in wall
time and in process CPU time, so a busy, shared machine only ever slows a chunk down and both
sides see the same machine. Prints microseconds per step for both and the cost ratio
new / reference (1.000 = same cost). A bare PyBullet loop of the new env's physics
(``bench_env.BareLoop``: the same bodies, substeps, force and torque calls and state reads)
runs in the same rounds, the fixed reference that neither checkout can slow down: ``new/bare``
is the new env's step over it.

    .venv/bin/python scripts/bench_compare.py --reference /tmp/base [--rounds 40 --chunk 500]
        [--ids SGCRod-v1 SGCPoint-v1] [--pair SGCRod-v1=SGCRod-v0]

``--pair NEW=OLD`` sets this checkout's id NEW against the reference's id OLD (another version
of the same task: a reference checkout from before a version change), on the same scene.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from bench_env import BareLoop, hover_action  # scripts/ is on the path when run as a script

HERE = Path(__file__).resolve().parents[1]


def load_sgc_env(checkout: Path) -> Any:
    """``sgc_env`` imported from ``checkout``, after forgetting any other copy's modules."""
    for name in [m for m in sys.modules if m == "sgc_env" or m.startswith("sgc_env.")]:
        del sys.modules[name]
    sys.path.insert(0, str(checkout))
    try:
        package = importlib.import_module("sgc_env")
        importlib.import_module("sgc_env.envs")
    finally:
        sys.path.remove(str(checkout))
    return package


def chunk_us(env: Any, steps: int, action: np.ndarray) -> tuple[float, float]:
    """(wall, CPU) microseconds per env.step over ``steps`` steps (resets included, rare)."""
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset(options={"scenario": env.scenario})
    return (time.perf_counter() - wall) / steps * 1e6, (time.process_time() - cpu) / steps * 1e6


def fixed_env(package: Any, kwargs: dict[str, Any]) -> Any:
    """An SGCEnv of ``package`` on the scenario the registered kwargs give at seed 0."""
    made = package.envs.SGCEnv(**kwargs)
    made.reset(seed=0)
    view = {k: v for k, v in kwargs.items() if k in ("observation", "reward")}
    env = package.envs.SGCEnv(made.scenario, **view)  # the id's view and reward cost per step
    made.close()
    env.reset()
    return env


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, required=True, help="the other checkout")
    parser.add_argument("--rounds", type=int, default=40)
    parser.add_argument("--chunk", type=int, default=500, help="steps per timed chunk")
    parser.add_argument("--ids", nargs="+", help="only these ids (default: every shared id)")
    parser.add_argument(
        "--pair", action="append", default=[], metavar="NEW=OLD",
        help="this checkout's id NEW against the reference's id OLD (repeatable)",
    )  # fmt: skip
    args = parser.parse_args()
    reference = load_sgc_env(args.reference.resolve())
    new = load_sgc_env(HERE)
    # ids both checkouts register: a newer id's kwargs may name arguments the reference lacks
    pairs = {k: k for k, v in new._REGISTRY.items()
             if v[0].endswith(":SGCEnv") and k in reference._REGISTRY
             and (args.ids is None or k in args.ids)}  # fmt: skip
    for pair in args.pair:
        newest, _, old = pair.partition("=")
        if newest not in new._REGISTRY or old not in reference._REGISTRY:
            parser.error(f"--pair {pair}: NEW must be registered here and OLD at the reference")
        pairs[f"{newest}={old}"] = old
    print(
        f"{'id':18} {'ref us/step':>12} {'new us/step':>12} {'wall new/ref':>13} "
        f"{'ref cpu us':>11} {'new cpu us':>11} {'cpu new/ref':>12} {'bare us':>8} {'new/bare':>9}"
    )
    for env_id, old in pairs.items():
        kwargs, ref_kwargs = new._REGISTRY[env_id.partition("=")[0]][1], reference._REGISTRY[old][1]
        envs = {"ref": fixed_env(reference, ref_kwargs), "new": fixed_env(new, kwargs)}
        action = hover_action(envs["new"])
        bare = BareLoop(envs["new"])
        best = {side: [float("inf"), float("inf")] for side in envs}
        best_bare = float("inf")
        for r in range(args.rounds):
            for side in ("ref", "new") if r % 2 == 0 else ("new", "ref"):  # ABBA: no order bias
                wall, cpu = chunk_us(envs[side], args.chunk, action)
                best[side] = [min(best[side][0], wall), min(best[side][1], cpu)]
            best_bare = min(best_bare, bare.run_us(args.chunk))
        (rw, rc), (nw, nc) = best["ref"], best["new"]
        print(
            f"{env_id:18} {rw:12.1f} {nw:12.1f} {nw / rw:13.3f} {rc:11.1f} {nc:11.1f} "
            f"{nc / rc:12.3f} {best_bare:8.1f} {nw / best_bare:9.2f}"
        )
        bare.sim.close()
        for env in envs.values():
            env.close()


if __name__ == "__main__":
    main()
