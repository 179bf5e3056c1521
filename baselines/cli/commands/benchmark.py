"""``sgc benchmark``: recipes x env ids x seeds, trained, scored and aggregated (IQM + CI).

Writes ``OUT/runs/<env>/<recipe>/seed<N>/`` per run (``config.json``, ``command.txt``, the
models, ``result.json``) and ``OUT/leaderboard.{md,json}`` plus one PNG per env
(performance profile and learning curves). Rerunning the same command skips finished runs
(and failed ones unless ``--retry-failed``); a run is finished once its ``result.json`` is
written, so a benchmark killed mid-grid (even by SIGKILL) resumes where it was. Two
benchmarks on one ``--out`` share the work: each run is claimed by one of them
(:mod:`baselines.benchmark.claims`) and every file is written atomically. The work is
:mod:`baselines.benchmark.driver`'s; see docs/agents.md.
"""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from baselines.cli.checks import env_kwargs, error_exit, out_dir
from baselines.cli.console import make_console

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    recipes = parser.add_argument_group("recipes (one or both)")
    recipes.add_argument(
        "--algo",
        action="append",
        metavar="ALGO",
        help="ppo, sac, td3, her; repeat or comma-separate: one recipe each",
    )
    recipes.add_argument("--recipes", metavar="YAML",
                         help="recipes file: recipes: [{name, algo, hyperparams, timesteps, "
                         "env_kwargs, train}]")  # fmt: skip
    recipes.add_argument("--hyperparams", default=None, help="folder of <algo>.yml for --algo")
    recipes.add_argument(
        "--env-kwargs", type=env_kwargs, default=None, help="JSON dict for gym.make (--algo)"
    )
    recipes.add_argument("--timesteps", type=int, default=None, help="steps per run (--algo)")
    recipes.add_argument(
        "--time-budget", type=float, default=None, metavar="SECONDS",
        help="seconds of training per run (--algo); --timesteps is then the upper bound",
    )  # fmt: skip
    recipes.add_argument(
        "--only", action="append", metavar="NAME",
        help="run only these recipes of --recipes/--algo (repeat or comma-separate)",
    )  # fmt: skip
    parser.add_argument("--env", action="append", required=True, metavar="ID",
                        help="env id; repeat or comma-separate")  # fmt: skip
    parser.add_argument("--seeds", type=int, default=3, help="training seeds per cell")
    parser.add_argument("--first-seed", type=int, default=0, help="seeds are first .. first+N-1")
    parser.add_argument(
        "--eval-episodes",
        type=int,
        default=50,
        help="held-out episodes scoring each run's best and final model",
    )
    parser.add_argument("--test-seed", type=int, default=20_000, help="first held-out seed")
    parser.add_argument(
        "--eval-freq",
        type=int,
        default=0,
        help="env steps between learning-curve points (0: four per run)",
    )
    parser.add_argument(
        "--curve-episodes",
        type=int,
        default=10,
        help="episodes per learning-curve point (they pick the best model)",
    )
    parser.add_argument("--eval-seed", type=int, default=10_000, help="first learning-curve seed")
    parser.add_argument("--out", type=out_dir, default=Path("runs/benchmark"),
                        help="folder of the runs and the leaderboard")  # fmt: skip
    parser.add_argument("--backend", choices=("local", "ray"), default="local")
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="local: processes (default: cores); ray: CPUs of a new instance",
    )
    parser.add_argument("--address", default=None, help="ray: cluster address (or 'auto')")
    parser.add_argument("--cpus-per-run", type=float, default=1.0, help="ray: CPUs per task")
    parser.add_argument("--retry-failed", action="store_true", help="rerun runs that failed")
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    parser.add_argument(
        "--report-only", action="store_true",
        help="run nothing: write the leaderboard from the runs finished so far",
    )  # fmt: skip


def _split(values: list[str] | None) -> list[str]:
    return [p.strip() for v in values or [] for p in v.split(",") if p.strip()]


def run(args: argparse.Namespace) -> int:

    from baselines.benchmark.backends import make_backend
    from baselines.benchmark.driver import benchmark_grid, pending_runs, report, run_grid
    from baselines.cli.console import RunProgress

    console = make_console()
    try:
        grid = benchmark_grid(
            algos=_split(args.algo), recipe_file=args.recipes, only=_split(args.only),
            env_ids=_split(args.env), seeds=args.seeds, first_seed=args.first_seed,
            hyperparams=args.hyperparams, env_kwargs=args.env_kwargs, timesteps=args.timesteps,
            time_budget_s=args.time_budget, eval_freq=args.eval_freq,
            curve_episodes=args.curve_episodes, eval_episodes=args.eval_episodes,
            eval_seed=args.eval_seed, test_seed=args.test_seed,
        )  # fmt: skip
        backend = make_backend(args.backend, args.workers, args.address, args.cpus_per_run)
    except ValueError as exc:
        return error_exit("benchmark", exc)
    root = args.out
    finished, failed_before, todo = pending_runs(grid, root, args.retry_failed)
    todo = [] if args.report_only else todo
    print(f"{len(grid)} runs: {len(finished)} finished before, {len(failed_before)} failed "
          f"before{' (retrying)' if args.retry_failed else ' (skipped; --retry-failed)'}, "
          f"{len(todo)} to run on {backend.description}", flush=True)  # fmt: skip
    with RunProgress(console, len(todo)) as shown:
        elsewhere = run_grid(todo, backend, root, shown.started, shown.finished, shown.elsewhere)
    if elsewhere:
        print(f"{len(elsewhere)} run(s) left to another sgc benchmark on {root} (running or "
              f"finished there): {', '.join(elsewhere)}", flush=True)  # fmt: skip
    argv = getattr(args, "argv", ["benchmark"])
    meta = {"command": shlex.join(["sgc", *(w for w in argv if w != "--report-only")]),
            "eval_episodes": args.eval_episodes, "test_seed": args.test_seed,
            "eval_seed": args.eval_seed}  # fmt: skip
    try:
        written, failed = report(grid, root, meta, plots=not args.no_plots)
    except ValueError as exc:
        return error_exit("benchmark", exc)
    print((root / "leaderboard.md").read_text())
    print("wrote " + ", ".join(str(p) for p in written))
    return 1 if failed else 0
