"""``sgc evaluate``: score one or more policies on one or more envs with the shared harness.

One env and one policy: DIR (default ``runs/evaluate/<env>/<policy>``) gets ``goals.csv``,
``summary.json``, ``goal_errors.png`` and ``speed_profile.png``. Several (``--policy a,b``,
``--env all``): each pair goes to ``DIR/<env>/<policy>`` (default DIR ``runs/evaluate``) and
DIR also gets ``scorecard.json`` and ``scorecard.md``, the comparison table printed.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from baselines.cli.checks import (
    add_trust_argument,
    error_exit,
    known_env_id,
    nonneg_float,
    nonneg_int,
    out_dir,
    positive_float,
    positive_int,
    staged_output,
    trust_model,
)
from sgc_env.defaults import EVAL_SEED, ORIENTATION_TOLERANCE, POSITION_TOLERANCE

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--policy", action="append", metavar="SPEC",
        help="expert | expert-paper | expert-matched | expert-smooth | dynamic-constraints | "
        "minimum-jerk | random | path to an SB3 .zip; "
        "repeat or comma-separate for a comparison (default: expert)",
    )  # fmt: skip
    parser.add_argument(
        "--env", action="append", metavar="ID",
        help="environment id, repeat or comma-separate; 'all' = every flat-observation SGC "
        "id (default: SGCPoint-v1)",
    )  # fmt: skip
    parser.add_argument(
        "--episodes", type=positive_int, default=5, help="episodes per pair"
    )
    parser.add_argument(
        "--seed", type=nonneg_int, default=EVAL_SEED,
        help="episode k uses seed + k",
    )  # fmt: skip
    parser.add_argument(
        "--num-envs", type=positive_int, default=1, metavar="N",
        help="run the episodes N at a time on the batched env (one PyBullet world; the same "
        "episodes as N=1 up to a model's batched float rounding; default 1)",
    )  # fmt: skip
    parser.add_argument("--out", type=out_dir, default=None, help="output folder (see above)")
    parser.add_argument(
        "--tolerance-position", type=positive_float, default=POSITION_TOLERANCE, metavar="M",
        help="success: position error at the goal's tick within this",
    )  # fmt: skip
    parser.add_argument(
        "--tolerance-orientation", type=positive_float, default=ORIENTATION_TOLERANCE,
        metavar="RAD", help="success: orientation error at the goal's tick within this",
    )  # fmt: skip
    parser.add_argument(
        "--tolerance-time", type=nonneg_float, default=0.0, metavar="S",
        help="success: also count a tick within S seconds of the goal's time (default 0: "
        "at the goal's time only)",
    )  # fmt: skip
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    parser.add_argument(
        "--wide", action="store_true",
        help="print every scorecard column (default: a compact table that fits 80 columns)",
    )  # fmt: skip
    add_trust_argument(parser)


def _split(values: Sequence[str] | None, default: str) -> list[str]:
    items = [part.strip() for v in (values or [default]) for part in v.split(",")]
    return [i for i in items if i]


def _write_pair(result: Any, out: Path, plots: bool) -> None:
    from baselines.evaluation.scorecards import write_pair

    write_pair(result, out)
    if plots:
        from baselines.figures.plots import plot_evaluation

        plot_evaluation(result, out)


def run(args: argparse.Namespace) -> int:
    from baselines.cli import console as show
    from baselines.evaluation.scorecards import evaluate_pairs, expand_envs, write_scorecard
    from baselines.policies import policy_labels, trusted_models
    from sgc_env.metrics import Tolerances

    console = show.make_console(args.wide)
    try:
        policies = _split(args.policy, "expert")
        labels = policy_labels(policies)
        envs = expand_envs(_split(args.env, "SGCPoint-v1"))
        tolerances = Tolerances(
            args.tolerance_position, args.tolerance_orientation, args.tolerance_time
        )
        for env_id in envs:
            known_env_id(env_id)
    except ValueError as exc:
        return error_exit("evaluate", exc)
    single = len(policies) == 1 and len(envs) == 1
    root = args.out or Path("runs/evaluate", *([envs[0], labels[0]] if single else []))
    pairs = evaluate_pairs(
        policies, labels, envs, episodes=args.episodes, seed=args.seed, tolerances=tolerances,
        num_envs=args.num_envs,
    )  # fmt: skip
    summaries = []
    # Written next to the output folder and moved in at the end: an interrupted run leaves
    # the earlier results whole.
    with staged_output(root) as stage, trusted_models(trust_model(args, "evaluate")):
        try:
            for env_id, label, result in pairs:
                folder = Path() if single else Path(env_id) / label
                _write_pair(result, stage / folder, not args.no_plots)
                summaries.append(result.summary)
                if single:
                    console.print(show.goal_table(result.rows, args.wide))
                console.print(f"[dim]{env_id} / {label}: done, goes to {root / folder}[/dim]")
        except ValueError as exc:
            return error_exit("evaluate", exc)
        if not single:
            write_scorecard(summaries, stage)
    title = f"{args.episodes} episode(s) from seed {args.seed}"
    console.print(show.scorecard_table(summaries, title, args.wide))
    smooth_title = "smoothness: LDLJ over the track, one-tick change of acceleration (kink)"
    smooth = show.SMOOTHNESS_WIDE_COLUMNS if args.wide else show.SMOOTHNESS_COLUMNS
    console.print(show.scorecard_table(summaries, smooth_title, args.wide, columns=smooth))
    console.print(f"[dim]wrote {root}[/dim]")
    console.print(show.summary_line(summaries[0]) if single else show.goals_met_line(summaries))
    return 0
