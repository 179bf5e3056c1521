"""``sgc evaluate``: score one or more policies on one or more envs with the shared harness.

One env and one policy: DIR (default ``runs/evaluate/<env>/<policy>``) gets ``goals.csv``,
``summary.json``, ``goal_errors.png`` and ``speed_profile.png``. Several (``--policy a,b``,
``--env all``): each pair goes to ``DIR/<env>/<policy>`` (default DIR ``runs/evaluate``) and
DIR also gets ``scorecard.json`` and ``scorecard.md``, the comparison table printed.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Mapping, Sequence
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

__all__ = [
    "SCORECARD_COLUMNS",
    "SMOOTHNESS_COLUMNS",
    "SMOOTHNESS_WIDE_COLUMNS",
    "add_arguments",
    "expand_envs",
    "markdown_table",
    "run",
]

#: (summary key, column title, format) of the comparison table.
SCORECARD_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("env_id", "env", "s"),
    ("policy", "policy", "s"),
    ("return_mean", "return", ".1f"),
    ("success_rate", "success", ".2f"),
    ("position_error_max", "pos err max (m)", ".1e"),
    ("orientation_error_max", "ori err max (rad)", ".1e"),
    ("position_closest_offset_abs_max", "closest offset abs max (s)", ".3f"),
    ("sparc_track_mean", "SPARC track", ".2f"),
    ("speed_minima_mean", "speed minima / ep", ".1f"),
    ("goal_speed_ratio_min", "goal speed ratio min", ".3f"),
    ("velocity_jump_max", "vel jump max (m/s)", ".3f"),
    ("acceleration_kink_max", "kink (m/s²)", ".2f"),
    ("angular_acceleration_kink_max", "ang kink (rad/s²)", ".2f"),
    ("force_peak_max", "peak force (N)", ".1f"),
    ("force_sq_integral_mean", "force² ∫ (N² s)", ".0f"),
    ("terminated", "terminated", "d"),
)


#: The default table, readable at 80 columns (``--wide``: :data:`SCORECARD_COLUMNS`).
COMPACT_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("env_id", "env", "s"),
    ("policy", "policy", "s"),
    ("success_rate", "success", ".2f"),
    ("position_error_max", "pos err\nmax (m)", ".1e"),
    ("orientation_error_max", "ori err\nmax (rad)", ".1e"),
    ("position_closest_offset_abs_max", "offset\nmax (s)", ".3f"),
)

#: The smoothness table printed under the compact one: LDLJ over the whole track and the
#: largest one-tick change of acceleration (the kink), linear and angular (peaks: ``--wide``).
SMOOTHNESS_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("env_id", "env", "s"),
    ("policy", "policy", "s"),
    ("ldlj_track_mean", "LDLJ\ntrack", ".2f"),
    ("acceleration_kink_max", "kink\n(m/s²)", ".2f"),
    ("angular_ldlj_track_mean", "ang LDLJ\ntrack", ".2f"),
    ("angular_acceleration_kink_max", "ang kink\n(rad/s²)", ".2f"),
)

#: The smoothness table with ``--wide``: peaks and the angular velocity jump too.
SMOOTHNESS_WIDE_COLUMNS: tuple[tuple[str, str, str], ...] = (
    *SMOOTHNESS_COLUMNS[:4],
    ("acceleration_peak_max", "peak acc\n(m/s²)", ".1f"),
    *SMOOTHNESS_COLUMNS[4:],
    ("angular_acceleration_peak_max", "peak ang acc\n(rad/s²)", ".1f"),
    ("angular_velocity_jump_max", "ang vel jump\nmax (rad/s)", ".3f"),
)

#: Per-goal table of a single pair: (row key, full title, compact title, format).
GOAL_TABLE_COLUMNS: tuple[tuple[str, str, str, str], ...] = (
    ("body", "body", "body", "d"),
    ("goal", "goal", "goal", "d"),
    ("time", "time", "time", ".3f"),
    ("position_error", "position_error", "pos err", ".2e"),
    ("orientation_error", "orientation_error", "ori err", ".2e"),
    ("closest_approach_offset", "closest_approach_offset", "closest", "+.3f"),
    ("entry_offset", "entry_offset", "entry", "+.3f"),
    ("success", "success", "ok", "s"),
)


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
        "id (default: SGCPoint-v0)",
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
        "--tolerance-time", type=nonneg_float, default=None, metavar="S",
        help="success time tolerance (default: one control step)",
    )  # fmt: skip
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    parser.add_argument(
        "--wide", action="store_true",
        help="print every scorecard column (default: a compact table that fits 80 columns)",
    )  # fmt: skip
    add_trust_argument(parser)
    parser.add_argument(
        "--reward", default=None, metavar="MODE",
        help="the env's reward mode (gym.make(id, reward=MODE): schedule, distance, sparse); "
        "default: the env's own",
    )  # fmt: skip


def _split(values: Sequence[str] | None, default: str) -> list[str]:
    items = [part.strip() for v in (values or [default]) for part in v.split(",")]
    return [i for i in items if i]


def expand_envs(names: Sequence[str]) -> list[str]:
    """Env ids with ``all`` replaced by every SGC id whose observation is a flat Box."""
    import gymnasium as gym

    import sgc_env

    out: list[str] = []
    for name in names:
        if name != "all":
            out.append(name)
            continue
        for env_id in sgc_env.ENV_IDS:
            env = gym.make(env_id)
            flat = isinstance(env.observation_space, gym.spaces.Box)
            env.close()
            if flat:
                out.append(env_id)
    return list(dict.fromkeys(out))


def _format(value: Any, fmt: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if fmt == "s":
        return str(value)
    return format(value, fmt)


def markdown_table(summaries: Sequence[Mapping[str, Any]]) -> str:
    """The comparison table in GitHub markdown (one row per env and policy)."""
    head = "| " + " | ".join(title for _, title, _ in SCORECARD_COLUMNS) + " |"
    rule = "|" + "|".join("---" for _ in SCORECARD_COLUMNS) + "|"
    body = [
        "| " + " | ".join(_format(s.get(k), f) for k, _, f in SCORECARD_COLUMNS) + " |"
        for s in summaries
    ]
    return "\n".join([head, rule, *body]) + "\n"


def _table(title: str, wide: bool) -> Any:
    from rich import box
    from rich.table import Table

    if wide:
        return Table(title=title, box=box.SQUARE)
    return Table(title=title, box=box.SIMPLE_HEAD, pad_edge=False, collapse_padding=True)


def _rich_table(
    summaries: Sequence[Mapping[str, Any]],
    title: str,
    wide: bool = False,
    columns: Sequence[tuple[str, str, str]] | None = None,
) -> Any:
    table = _table(title, wide)
    if columns is None:
        columns = SCORECARD_COLUMNS if wide else COMPACT_COLUMNS
    for _, name, fmt in columns:
        text = fmt == "s"
        table.add_column(name, justify="left" if text else "right", overflow="fold")
    for s in summaries:
        table.add_row(*(_format(s.get(k), f) for k, _, f in columns))
    return table


def _goal_table(rows: Sequence[Mapping[str, Any]], wide: bool = False, limit: int = 40) -> Any:
    table = _table("episode 0, per goal", wide)
    for _, full, short, _ in GOAL_TABLE_COLUMNS:
        table.add_column(full if wide else short, justify="right")
    for row in [r for r in rows if r["episode"] == 0][:limit]:
        table.add_row(*(_format(row[key], fmt) for key, _, _, fmt in GOAL_TABLE_COLUMNS))
    return table


def _goals_met_line(summaries: Sequence[Mapping[str, Any]]) -> str:
    """Goals met per policy, summed over the envs: the comparison in one line."""
    met: dict[str, list[int]] = {}
    for s in summaries:
        counts = met.setdefault(str(s["policy"]), [0, 0])
        counts[0] += int(s.get("goals_met", 0))
        counts[1] += int(s.get("n_goals", 0))
    return "goals met: " + ", ".join(f"{p} {m}/{n}" for p, (m, n) in met.items())


def _write_pair(result: Any, out: Path, plots: bool) -> None:
    from baselines.evaluation import write_goals_csv, write_summary_json

    write_goals_csv(result.rows, out / "goals.csv")
    write_summary_json(result.summary, out / "summary.json")
    if not plots:
        return
    from baselines.cli.plots import plot_goal_errors, plot_speed_profile, trajectory_arrays

    title = f"{result.policy} on {result.env_id}"
    plot_goal_errors(result.rows, out / "goal_errors.png", title=title)
    first = result.episodes[0]
    if first.infos:
        traj = trajectory_arrays(first.infos, first.initial_info)
        plot_speed_profile(traj, first.goals, out / "speed_profile.png", title=f"{title}, ep 0")


def run(args: argparse.Namespace) -> int:
    from baselines.cli.console import make_console, summary_line
    from baselines.evaluation import evaluate, json_ready
    from baselines.policies import policy_labels, trusted_models
    from sgc_env.metrics import Tolerances

    console = make_console(args.wide)
    try:
        policies = _split(args.policy, "expert")
        labels = policy_labels(policies)
        envs = expand_envs(_split(args.env, "SGCPoint-v0"))
        tolerances = Tolerances(
            args.tolerance_position, args.tolerance_orientation, args.tolerance_time
        )
        for env_id in envs:
            known_env_id(env_id)
    except ValueError as exc:
        return error_exit("evaluate", exc)
    single = len(policies) == 1 and len(envs) == 1
    if single:
        root = args.out or Path("runs/evaluate") / envs[0] / labels[0]
    else:
        root = args.out or Path("runs/evaluate")
    summaries = []
    # Written next to the output folder and moved in at the end: an interrupted run leaves
    # the earlier results whole.
    with staged_output(root) as stage, trusted_models(trust_model(args, "evaluate")):
        for env_id in envs:
            for spec, label in zip(policies, labels, strict=True):
                folder = Path() if single else Path(env_id) / label
                try:
                    result = evaluate(
                        spec, env_id, args.episodes, args.seed, tolerances=tolerances,
                        label=label, num_envs=args.num_envs,
                        env_kwargs=None if args.reward is None else {"reward": args.reward},
                    )  # fmt: skip
                except ValueError as exc:
                    return error_exit("evaluate", exc)
                _write_pair(result, stage / folder, not args.no_plots)
                summaries.append(result.summary)
                if single:
                    console.print(_goal_table(result.rows, args.wide))
                console.print(f"[dim]{env_id} / {label}: done, goes to {root / folder}[/dim]")
        if not single:
            (stage / "scorecard.json").write_text(
                json.dumps(json_ready(summaries), indent=2, allow_nan=False) + "\n"
            )
            (stage / "scorecard.md").write_text(markdown_table(summaries))
    title = f"{args.episodes} episode(s) from seed {args.seed}"
    console.print(_rich_table(summaries, title, args.wide))
    smooth_title = "smoothness: LDLJ over the track, one-tick change of acceleration (kink)"
    smooth = SMOOTHNESS_WIDE_COLUMNS if args.wide else SMOOTHNESS_COLUMNS
    console.print(_rich_table(summaries, smooth_title, args.wide, columns=smooth))
    console.print(f"[dim]wrote {root}[/dim]")
    console.print(summary_line(summaries[0]) if single else _goals_met_line(summaries))
    return 0
