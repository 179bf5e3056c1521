"""``sgc rollout``: one scenario, one controller, everything written down.

The scenario is a built-in name or a YAML file (``--scenario``) or the one an env id draws
for a seed (``--env ID --seed N``). DIR (default ``runs/rollout/<scenario>/<policy>``, from
the command line: a scenario file's stem, a built-in name or the env id) gets
``trajectory.npz`` (time, per-body deviations, poses, velocities, force, torque, goal
indices; goal times and nails), ``summary.json`` (the episode's scorecard) and the plots:
``deviation.png`` (each component of D and phi against time, goal times dotted),
``path3d.png``, ``speed.png``, and ``figure1_vs_2.png``: dynamic constraints against
sequential-goal constraints (the expert) on the same courses, the paper's Figures 1 and 2
side by side. ``--video`` adds ``rollout.mp4`` (TinyRenderer frames via imageio), ``--gltf``
``rollout.glb`` (the motion as a keyframed glTF scene, :mod:`sgc_env.export.gltf`).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

from baselines.cli.checks import (
    add_trust_argument,
    error_exit,
    nonneg_int,
    out_dir,
    staged_output,
    trust_model,
)
from baselines.cli.console import make_console

__all__ = ["add_arguments", "default_out", "folder_name", "make_env", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--scenario", metavar="NAME|YAML", help="built-in name or YAML file")
    source.add_argument("--env", metavar="ID", help="env id whose seeded scenario to roll out")
    parser.add_argument("--seed", type=nonneg_int, default=0, help="reset seed (default 0)")
    parser.add_argument(
        "--policy", default="expert", metavar="SPEC",
        help="expert | dynamic-constraints | minimum-jerk | random | SB3 .zip (default expert)",
    )  # fmt: skip
    add_trust_argument(parser)
    parser.add_argument("--out", type=out_dir, default=None, help="output folder")
    parser.add_argument("--video", action="store_true", help="also write rollout.mp4")
    parser.add_argument(
        "--gltf", action="store_true",
        help="also write rollout.glb (the motion as a keyframed glTF scene, for Blender or a "
        "browser)",
    )  # fmt: skip
    parser.add_argument(
        "--no-compare", action="store_true",
        help="skip the dynamic-constraints vs SGC comparison figure",
    )  # fmt: skip


def make_env(scenario: str | None, env_id: str | None, render: bool) -> tuple[Any, str]:
    """The env to roll out and its name for titles (a scenario file's own ``name``, escaped:
    it is shown, never made a path; :func:`folder_name` is the output folder's)."""
    import gymnasium as gym

    import sgc_env
    from sgc_env.envs.sgc_env import SGCEnv
    from sgc_env.scenario.bounded import escaped

    mode = "rgb_array" if render else None
    if scenario is not None:
        loaded = sgc_env.load_scenario(scenario)
        return SGCEnv(scenario=loaded, render_mode=mode), escaped(loaded.name, 80)
    env_id = env_id or "SGCPoint-v1"
    sgc_env.check_env_id(env_id, "env")
    return gym.make(env_id, render_mode=mode), env_id


def folder_name(text: str) -> str:
    """A name from the command line as one harmless folder name: letters, digits and
    ``_.+-`` (anything else ``_``), never ``.``/``..`` or hidden."""
    slug = re.sub(r"[^A-Za-z0-9_.+-]", "_", text)[:80].lstrip(".")
    return slug or "_"


def default_out(args: argparse.Namespace, label: str) -> Path:
    """``runs/rollout/<scenario or env>/<policy>``, from the command line only: a scenario
    file's stem (its ``name`` field could be ``../..`` or absolute), a built-in name or an
    env id."""
    source = Path(args.scenario).stem if args.scenario else (args.env or "SGCPoint-v1")
    return Path("runs/rollout") / folder_name(source) / folder_name(label)


def run(args: argparse.Namespace) -> int:

    from baselines.cli.console import smoothness_line
    from baselines.evaluation.harness import run_episode
    from baselines.figures.rollout_files import write_rollout
    from baselines.policies import make_policy, policy_label

    console = make_console()
    try:
        env, name = make_env(args.scenario, args.env, args.video)
    except ValueError as exc:
        return error_exit("rollout", exc)
    try:
        label = policy_label(args.policy)
        out = args.out or default_out(args, label)
        trust = trust_model(args, "rollout")
        policy = make_policy(args.policy, env, seed=args.seed, trust_model=trust)
        frames: list[Any] | None = [] if args.video else None
        record = run_episode(policy, env, args.seed, keep_infos=True, frames=frames)
        title = f"{label} on {name} (seed {args.seed})"
        # written next to the output folder and moved in at the end, never through a link
        with staged_output(out) as stage:
            write_rollout(stage, env, record, title, args.policy, args.seed,
                          not args.no_compare, frames, gltf=args.gltf)  # fmt: skip
    except ValueError as exc:
        return error_exit("rollout", exc)
    finally:
        env.close()
    card = record.card
    console.print(
        f"{title}: {record.steps} steps, success {card['success_rate']:.2f}, "
        f"position error max {card['position_error_max']:.2e} m, "
        f"orientation error max {card['orientation_error_max']:.2e} rad"
    )
    console.print(smoothness_line(card))
    console.print(f"[dim]wrote {out}[/dim]")
    return 0
