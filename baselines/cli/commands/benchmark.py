"""``sgc benchmark``: recipes x env ids x seeds, trained, scored and aggregated (IQM + CI).

Writes ``OUT/runs/<env>/<recipe>/seed<N>/`` per run (``config.json``, ``command.txt``, the
models, ``result.json``) and ``OUT/leaderboard.{md,json}`` plus one PNG per env
(performance profile and learning curves). Rerunning the same command skips finished runs
(and failed ones unless ``--retry-failed``); a run is finished once its ``result.json`` is
written, so a benchmark killed mid-grid (even by SIGKILL) resumes where it was. Two
benchmarks on one ``--out`` share the work: each run is claimed by one of them
(:mod:`baselines.benchmark.claims`) and every file is written atomically. See docs/agents.md.
"""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path
from typing import Any

from baselines.cli.checks import env_kwargs, error_exit, out_dir

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


def _grid(args: argparse.Namespace) -> list[Any]:
    from baselines.benchmark.grid import build_grid, load_recipes, recipes_from_algos

    recipes = []
    if args.algo:
        recipes += recipes_from_algos(_split(args.algo), args.hyperparams, args.env_kwargs,
                                      args.timesteps, args.time_budget)  # fmt: skip
    if args.recipes:
        recipes += load_recipes(args.recipes)
    if args.only:
        wanted = _split(args.only)
        unknown = sorted(set(wanted) - {r.name for r in recipes})
        if unknown:
            raise ValueError(f"--only: no recipe named {unknown} (known: "
                             f"{sorted(r.name for r in recipes)})")  # fmt: skip
        recipes = [r for r in recipes if r.name in wanted]
    if args.seeds < 1 or args.first_seed < 0:
        raise ValueError(f"--seeds must be >= 1 and --first-seed >= 0, got {args.seeds}, "
                         f"{args.first_seed}")  # fmt: skip
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    return build_grid(
        recipes, _split(args.env), seeds, eval_freq=args.eval_freq,
        curve_episodes=args.curve_episodes, eval_episodes=args.eval_episodes,
        eval_seed=args.eval_seed, test_seed=args.test_seed,
    )  # fmt: skip


def _run_grid(todo: list[Any], backend: Any, root: Path, console: Any) -> list[str]:
    """Run ``todo``; the ids of runs left to another ``sgc benchmark`` on this folder."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from baselines.benchmark.claims import RunClaims
    from baselines.benchmark.execute import RESULT_FILE

    counts = {"running": 0, "done": 0, "failed": 0}
    folders = {spec.run_id: spec.folder(root) for spec in todo}
    claims, elsewhere = RunClaims(), []

    def status() -> str:
        return f"done {counts['done']}, running {counts['running']}, failed {counts['failed']}"

    columns = (TextColumn("[bold]runs"), BarColumn(), MofNCompleteColumn(),
               TextColumn("{task.description}"), TimeElapsedColumn())  # fmt: skip
    with Progress(*columns, console=console, disable=not console.is_terminal) as progress:
        task = progress.add_task(status(), total=len(todo))

        def started(run_id: str) -> None:
            counts["running"] += 1
            progress.update(task, description=status())

        def claim(spec: dict[str, Any]) -> bool:
            """Another benchmark on this folder may hold the run, or have finished it."""
            folder = folders[spec["run_id"]]
            if claims.claim(folder) and not (folder / RESULT_FILE).is_file():
                return True
            claims.release(folder)
            elsewhere.append(spec["run_id"])
            progress.update(task, advance=1)
            return False

        try:
            outcomes = backend.run([s.to_dict() for s in todo], on_start=started, claim=claim)
            for outcome in outcomes:
                _record(outcome, folders[outcome["run_id"]], counts, console, progress)
                claims.release(folders[outcome["run_id"]])
                progress.update(task, advance=1, description=status())
        finally:
            claims.release_all()
    return elsewhere


def _record(outcome: dict[str, Any], folder: Path, counts: dict[str, int], console: Any,
            progress: Any) -> None:  # fmt: skip
    """Write one run's outcome and say how it went."""
    from baselines.benchmark.execute import write_outcome

    write_outcome(outcome, folder)
    ok = outcome["status"] == "finished"
    counts["running"] -= 1
    counts["done" if ok else "failed"] += 1
    verdict = "finished" if ok else "FAILED"
    line = f"{outcome['run_id']}: {verdict} in {outcome['wall_time_s']:.0f} s"
    if not ok:
        line += f" ({outcome['error']}; see {folder}/failed.json)"
    if console.is_terminal:
        progress.console.print(line)
    else:
        print(line, flush=True)


def run(args: argparse.Namespace) -> int:
    from rich.console import Console

    from baselines.benchmark.aggregate import aggregate_runs
    from baselines.benchmark.backends import make_backend
    from baselines.benchmark.execute import FAILED_FILE, RESULT_FILE
    from baselines.benchmark.report import write_report
    from baselines.benchmark.results import read_record

    console = Console()
    try:
        grid = _grid(args)
        backend = make_backend(args.backend, args.workers, args.address, args.cpus_per_run)
    except ValueError as exc:
        return error_exit("benchmark", exc)
    root = args.out
    finished = [s for s in grid if (s.folder(root) / RESULT_FILE).is_file()]
    failed_before = [s for s in grid if s not in finished
                     and (s.folder(root) / FAILED_FILE).is_file()]  # fmt: skip
    todo = [s for s in grid if s not in finished
            and (args.retry_failed or s not in failed_before)]  # fmt: skip
    if args.report_only:
        todo = []
    print(f"{len(grid)} runs: {len(finished)} finished before, {len(failed_before)} failed "
          f"before{' (retrying)' if args.retry_failed else ' (skipped; --retry-failed)'}, "
          f"{len(todo)} to run on {backend.description}", flush=True)  # fmt: skip
    elsewhere = _run_grid(todo, backend, root, console)
    if elsewhere:
        print(f"{len(elsewhere)} run(s) left to another sgc benchmark on {root} (running or "
              f"finished there): {', '.join(elsewhere)}", flush=True)  # fmt: skip
    try:
        results = [read_record(s.folder(root) / RESULT_FILE, s, finished=True) for s in grid
                   if (s.folder(root) / RESULT_FILE).is_file()]  # fmt: skip
        failed = [read_record(s.folder(root) / FAILED_FILE, s, finished=False) for s in grid
                  if (s.folder(root) / FAILED_FILE).is_file()]  # fmt: skip
    except ValueError as exc:
        return error_exit("benchmark", exc)
    meta = {
        "command": shlex.join(
            ["sgc", *(w for w in getattr(args, "argv", ["benchmark"]) if w != "--report-only")]
        ),
        "eval_episodes": args.eval_episodes, "test_seed": args.test_seed,
        "eval_seed": args.eval_seed, "runs": len(grid), "finished": len(results),
        "failed": len(failed),
    }  # fmt: skip
    written = write_report(aggregate_runs(results, failed), results, meta, root,
                           plots=not args.no_plots)  # fmt: skip
    print((root / "leaderboard.md").read_text())
    print("wrote " + ", ".join(str(p) for p in written))
    return 1 if failed else 0
