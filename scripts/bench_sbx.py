"""Training throughput, SB3 (PyTorch) against SBX (JAX), on CPU: same env, network, settings.

Needs a venv with both (SBX is not a project dependency)::

    python3 -m venv /work/scratch-sbx
    /work/scratch-sbx/bin/pip install sbx-rl torch==2.13.0 gymnasium==1.4.0 pybullet pyyaml \
        scipy matplotlib imageio rich tqdm
    PYTHONPATH=$PWD /work/scratch-sbx/bin/python scripts/bench_sbx.py [--ppo-steps 8192]

Each library trains PPO and SAC on SGCPoint-v1 with the hyperparameters of
baselines/hyperparams/{ppo,sac}.yml (256-256 networks; PPO 4 envs x 512 steps, 10 epochs, batch 256;
SAC one gradient step of batch 256 per env step, from step 100). Every measurement follows
a short warm-up run of the same model (JIT compilation, allocator), and the libraries
alternate (``--repeats``), so both see the same machine load. Printed: env steps per second
of ``learn`` and the SBX/SB3 ratio. Both use one CPU thread (torch.set_num_threads(1); XLA
with its Eigen thread pool off), as the benchmark runs one run per core.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault(
    "XLA_FLAGS", "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
)

import numpy as np  # noqa: E402
import torch  # noqa: E402

import sgc_env  # noqa: E402, F401  (registers the ids)
from baselines.agents.hyperparams import load_hyperparams  # noqa: E402

ENV_ID = "SGCPoint-v1"


def _model(lib: str, algo: str, seed: int):
    import sbx
    import stable_baselines3 as sb3
    from stable_baselines3.common.env_util import make_vec_env

    hp = load_hyperparams(algo, ENV_ID)
    kwargs = dict(hp.algo_kwargs)
    policy_kwargs = dict(kwargs.pop("policy_kwargs", {}) or {})
    if algo == "sac":  # gradient steps from the start: the warm-up compiles them
        kwargs["learning_starts"] = 100
    cls = getattr(sb3 if lib == "sb3" else sbx, algo.upper())
    env = make_vec_env(ENV_ID, n_envs=hp.n_envs, seed=seed)
    return cls(hp.policy, env, seed=seed, policy_kwargs=policy_kwargs, verbose=0, **kwargs)


def _rate(lib: str, algo: str, steps: int, warmup: int) -> float:
    model = _model(lib, algo, seed=0)
    model.learn(warmup)
    started = time.perf_counter()
    before = model.num_timesteps
    model.learn(steps, reset_num_timesteps=False)
    return (model.num_timesteps - before) / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ppo-steps", type=int, default=8192)
    parser.add_argument("--sac-steps", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    torch.set_num_threads(1)
    import jax
    import sbx
    import stable_baselines3 as sb3

    print(f"torch {torch.__version__}, SB3 {sb3.__version__}, jax {jax.__version__}, "
          f"SBX {sbx.__version__}, {ENV_ID}, devices {jax.devices()}")  # fmt: skip
    plans = {"ppo": (args.ppo_steps, 2048), "sac": (args.sac_steps, 300)}
    rates: dict[tuple[str, str], list[float]] = {}
    for _ in range(args.repeats):
        for algo, (steps, warmup) in plans.items():
            for lib in ("sb3", "sbx"):
                rates.setdefault((algo, lib), []).append(_rate(lib, algo, steps, warmup))
    print("| algorithm | SB3 steps/s | SBX steps/s | SBX / SB3 |")
    print("|---|---|---|---|")
    for algo in plans:
        sb3_rate = float(np.median(rates[(algo, "sb3")]))
        sbx_rate = float(np.median(rates[(algo, "sbx")]))
        print(f"| {algo.upper()} | {sb3_rate:.0f} | {sbx_rate:.0f} | {sbx_rate / sb3_rate:.2f} |")
    print("per repeat:", {f"{a}/{lib}": [round(r) for r in v] for (a, lib), v in rates.items()})


if __name__ == "__main__":
    main()
