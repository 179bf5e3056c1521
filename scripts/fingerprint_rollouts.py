"""Digest of seeded rollouts of every registered env: proves a refactor changed no output bit.

For every id in ``sgc_env.ENV_IDS`` and a few seeds it runs two episodes: seeded random
actions (slightly beyond the box, so clipping is exercised, plus one ``apply_impulse`` and a
``save_state``/``restore_state`` round trip) and the analytic expert's actions. The expert's
actions are recorded once into ``--actions`` (an ``.npz``) and replayed from there afterwards,
so later changes to the expert do not change the digest. Everything an env hands out is hashed
(sha256 over a canonical byte encoding): observations, rewards, terminated, truncated and every
info entry. One digest per id is printed; compare the output of two checkouts line by line.

    PYTHONPATH=$PWD .venv/bin/python scripts/fingerprint_rollouts.py --actions /tmp/fp.npz
"""

from __future__ import annotations

import argparse
import hashlib
import struct
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sgc_env

SEEDS = (0, 1, 2)
MAX_STEPS = 3000
IMPULSE_STEP = 7
SNAPSHOT_STEP = 11


def encode(value: Any) -> bytes:
    """A canonical byte encoding of what envs return (arrays, scalars, lists, dicts)."""
    if isinstance(value, np.ndarray):
        return b"A" + str(value.dtype).encode() + str(value.shape).encode() + value.tobytes()
    if isinstance(value, dict):
        return b"D" + b"".join(encode(k) + encode(value[k]) for k in sorted(value))
    if isinstance(value, list | tuple):
        return b"L" + str(len(value)).encode() + b"".join(encode(v) for v in value)
    if value is None:
        return b"N"
    if isinstance(value, bool | np.bool_):
        return b"T" if value else b"F"
    if isinstance(value, int | np.integer):
        return b"I" + str(int(value)).encode()
    if isinstance(value, float | np.floating):
        return b"R" + str(type(value).__name__).encode() + struct.pack("<d", float(value))
    if isinstance(value, str):
        return b"S" + value.encode()
    raise TypeError(f"cannot fingerprint a {type(value).__name__}")


def random_episode(env_id: str, seed: int, digest: Any) -> None:
    env = gym.make(env_id)
    obs, info = env.reset(seed=seed)
    digest.update(encode(obs) + encode(info))
    rng = np.random.default_rng(seed)
    shape = env.action_space.shape
    for step in range(MAX_STEPS):
        action = rng.uniform(-1.1, 1.1, shape).astype(np.float32)
        out = env.step(action)
        digest.update(b"".join(encode(v) for v in out))
        if step == IMPULSE_STEP:
            pushed = env.unwrapped.apply_impulse(0, rng.normal(0, 0.05, 3), rng.normal(0, 1e-3, 3))
            digest.update(encode(pushed))
        if step == SNAPSHOT_STEP:
            saved = env.unwrapped.save_state()
            env.step(rng.uniform(-1.0, 1.0, shape).astype(np.float32))
            digest.update(encode(env.unwrapped.restore_state(saved)))
        if out[2] or out[3]:
            break
    env.close()


def expert_actions(env_id: str, seed: int) -> np.ndarray:
    """The expert's actions on one episode (imported here only: recording needs baselines)."""
    from baselines.controllers.expert import SGCExpert

    env = gym.make(env_id)
    obs, _ = env.reset(seed=seed)
    expert = SGCExpert(env)
    actions = []
    for _ in range(MAX_STEPS):
        action, _ = expert.predict(obs)
        actions.append(action)
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    env.close()
    return np.asarray(actions)


def replay_episode(env_id: str, seed: int, actions: np.ndarray, digest: Any) -> None:
    env = gym.make(env_id)
    obs, info = env.reset(seed=seed)
    digest.update(encode(obs) + encode(info))
    for action in actions:
        digest.update(b"".join(encode(v) for v in env.step(action)))
    env.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--actions", type=Path, required=True,
        help="expert actions .npz: recorded there if missing, replayed if present",
    )  # fmt: skip
    args = parser.parse_args()
    recorded: dict[str, np.ndarray] = {}
    if args.actions.exists():
        with np.load(args.actions) as data:
            recorded = dict(data)
    fresh = {}
    for env_id in sgc_env.ENV_IDS:
        digest = hashlib.sha256()
        for seed in SEEDS:
            key = f"{env_id}/{seed}"
            if key not in recorded:
                fresh[key] = recorded[key] = expert_actions(env_id, seed)
            random_episode(env_id, seed, digest)
            replay_episode(env_id, seed, recorded[key], digest)
        print(f"{env_id:18} {digest.hexdigest()}")
    if fresh:
        np.savez_compressed(args.actions, **recorded)
        print(f"recorded {len(fresh)} expert episodes into {args.actions}")


if __name__ == "__main__":
    main()
