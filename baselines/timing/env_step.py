"""Control steps per second of every registered env against the bare loop of its physics.

Each id on its own view and reward, on the scenario it draws at seed 0; interleaved rounds,
the best of each kept (robust to a busy machine: other jobs only ever slow a round down).
Reset time is the mean ``env.reset()`` on the fixed scenario, and for the random-scene ids
also with the scene draw of every reset.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import gymnasium as gym

from baselines.timing.bare import BareLoop, env_step_us, fixed_env, hover_action, reset_us

__all__ = ["env_table"]


def env_table(
    ids: Sequence[str], steps: int, resets: int, rounds: int, draws: int
) -> Iterator[str]:
    """The table's lines, one id at a time as it is measured."""
    width = max(len(env_id) for env_id in ids)
    header = (
        f"{'id':{width}} {'env steps/s':>12} {'bare steps/s':>13} {'ratio':>6} "
        f"{'reset us':>9} {'draw+reset us':>14}"
    )
    yield header
    yield "-" * len(header)
    for env_id in ids:
        made, fixed = fixed_env(env_id)
        bare = BareLoop(fixed)
        action = hover_action(fixed)
        chunk = max(steps // rounds, 1)
        env_us = bare_us = fixed_reset = float("inf")
        for _ in range(rounds):
            env_us = min(env_us, env_step_us(fixed, chunk, action))
            bare_us = min(bare_us, bare.run_us(chunk))
            fixed_reset = min(fixed_reset, reset_us(fixed, max(resets // rounds, 1)))
        bare.close()
        random = "random_scenario" in gym.spec(env_id).kwargs
        draw = reset_us(made, draws) if random else float("nan")
        fixed.close()
        made.close()
        yield (
            f"{env_id:{width}} {1e6 / env_us:12.0f} {1e6 / bare_us:13.0f} {env_us / bare_us:6.2f} "
            f"{fixed_reset:9.1f} {draw:14.1f}"
        )
