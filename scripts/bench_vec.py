"""Env-steps/s and memory of the batched env against SB3's DummyVecEnv and SubprocVecEnv of
single envs, and PPO's steps/s on each, for N sub-envs per id, in one run.

Every (id, N, kind) is measured in a fresh child process, one after the other, so that memory
is that configuration's alone: ``rss`` is the process's resident memory after the run (for
``subproc`` plus its workers'), ``+rss`` the growth from before the env was made (the imports
of Python, torch and SB3 are the difference). Env steps: SB3's VecEnv API on all three kinds,
hover actions plus Gaussian noise (the same in every kind; episodes that end are reset and
their resets are timed too). PPO: ``n_steps = max(8, rollout // N)`` (``--rollout``, 2048),
one epoch, minibatch ``min(1024, N * n_steps)``, two rollouts timed after a warm-up one.
Ratios are against DummyVecEnv at the same N, measured in this run; read them, not the
absolute rates, on a busy machine (``--repeats`` runs the kinds in turn, keeps each's best).

    .venv/bin/python scripts/bench_vec.py --ids SGCRod-v1 --n 1 8 64 256 --ppo
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

KINDS = ("batched", "dummy", "subproc")


def _rss_mb(children: bool) -> float:
    import psutil

    proc = psutil.Process()
    procs = [proc, *proc.children(recursive=True)] if children else [proc]
    return sum(p.memory_info().rss for p in procs) / 2**20


def child(env_id: str, n: int, kind: str, steps: int, rollout: int) -> dict[str, float]:
    """One measurement (runs in its own process)."""
    import numpy as np

    from baselines.agents.sb3_vec_env import BatchedVecEnv, make_sgc_vec
    from baselines.timing.bare import hover_action

    before = _rss_mb(False)
    env = BatchedVecEnv(env_id, n) if kind == "batched" else make_sgc_vec(env_id, n, vec=kind)
    env.seed(0)
    env.reset()
    shape = env.action_space.shape
    hover = hover_action(env.get_attr("unwrapped", [0])[0])
    rng = np.random.default_rng(0)
    t_steps = max(steps // n, 10)
    actions = (hover + rng.normal(0.0, 0.1, (t_steps + 5, n, *shape))).astype(np.float32)
    for t in range(5):
        env.step(actions[t])
    started = time.perf_counter()
    for t in range(t_steps):
        env.step(actions[5 + t])
    rate = n * t_steps / (time.perf_counter() - started)
    out = {"env_steps_s": rate, "rss_mb": _rss_mb(kind == "subproc")}
    out["rss_growth_mb"] = out["rss_mb"] - before
    if rollout:
        import torch
        from stable_baselines3 import PPO

        torch.set_num_threads(1)
        n_steps = max(8, rollout // n)
        model = PPO(
            "MlpPolicy", env, n_steps=n_steps, batch_size=min(1024, n * n_steps), n_epochs=1,
            seed=0, device="cpu",
        )  # fmt: skip
        model.learn(n * n_steps)
        started = time.perf_counter()
        model.learn(2 * n * n_steps, reset_num_timesteps=False)
        out["ppo_steps_s"] = 2 * n * n_steps / (time.perf_counter() - started)
    env.close()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ids", nargs="+", default=None, help="default: every SGC id")
    parser.add_argument("--n", nargs="+", type=int, default=[1, 8, 64, 256])
    parser.add_argument("--kinds", nargs="+", choices=KINDS, default=list(KINDS))
    parser.add_argument("--steps", type=int, default=4000, help="env steps timed per config")
    parser.add_argument("--ppo", action="store_true", help="also time PPO on each")
    parser.add_argument("--rollout", type=int, default=2048, help="PPO's steps per rollout")
    parser.add_argument(
        "--repeats", type=int, default=1,
        help="run the kinds in turn this many times; the best rate of each is kept",
    )  # fmt: skip
    parser.add_argument(
        "--subproc-max", type=int, default=64,
        help="largest N for SubprocVecEnv (one process per sub-env)",
    )  # fmt: skip
    parser.add_argument("--child", nargs=5, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        env_id, n, kind, steps, rollout = args.child
        print(json.dumps(child(env_id, int(n), kind, int(steps), int(rollout))))
        return
    import sgc_env

    ids = args.ids or list(sgc_env.ENV_IDS)
    print(f"{'id':22} {'N':>4} {'kind':8} {'env-steps/s':>11} {'x dummy':>7} {'rss MB':>7} "
          f"{'+rss MB':>7} {'PPO steps/s':>11} {'x dummy':>7}")  # fmt: skip
    root = Path(__file__).resolve().parents[1]
    for env_id in ids:
        for n in args.n:
            rows: dict[str, dict[str, float]] = {}
            kinds = [k for k in args.kinds if k != "subproc" or n <= args.subproc_max]
            for _ in range(args.repeats):
                for kind in kinds:
                    cmd = [sys.executable, __file__, "--child", env_id, str(n), kind,
                           str(args.steps), str(args.rollout if args.ppo else 0)]  # fmt: skip
                    done = subprocess.run(cmd, capture_output=True, text=True, cwd=root)
                    if done.returncode:
                        print(f"{env_id:22} {n:>4} {kind:8} failed: {done.stderr[-300:]}")
                        continue
                    new = json.loads(done.stdout.strip().splitlines()[-1])
                    old = rows.setdefault(kind, new)
                    for key in ("env_steps_s", "ppo_steps_s"):
                        if key in new:
                            old[key] = max(old[key], new[key])
            ref = rows.get("dummy", {})
            for kind, r in rows.items():
                ratio = r["env_steps_s"] / ref["env_steps_s"] if ref else float("nan")
                ppo = r.get("ppo_steps_s", float("nan"))
                ppo_ratio = ppo / ref["ppo_steps_s"] if "ppo_steps_s" in ref else float("nan")
                print(
                    f"{env_id:22} {n:>4} {kind:8} {r['env_steps_s']:>11.0f} {ratio:>7.2f} "
                    f"{r['rss_mb']:>7.0f} {r['rss_growth_mb']:>7.0f} {ppo:>11.0f} "
                    f"{ppo_ratio:>7.2f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
