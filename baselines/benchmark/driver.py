"""A benchmark from its options to its leaderboard: the grid, which runs are left, running
them (claimed, so two benchmarks on one folder share the work), and the report.

``sgc benchmark`` is its command line; it only adds the progress display. A run is finished
once its ``result.json`` is written (:mod:`.execute`), so a benchmark killed mid-grid resumes
where it was; every file is written atomically.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from baselines.benchmark.aggregate import aggregate_runs
from baselines.benchmark.claims import RunClaims, report_lock
from baselines.benchmark.execute import FAILED_FILE, RESULT_FILE, write_outcome
from baselines.benchmark.grid import RunSpec, build_grid, load_recipes, recipes_from_algos
from baselines.benchmark.report import write_report
from baselines.benchmark.results import read_record

__all__ = ["benchmark_grid", "collect_results", "pending_runs", "report", "run_grid"]


def benchmark_grid(
    *,
    algos: Sequence[str],
    recipe_file: str | Path | None,
    only: Sequence[str],
    env_ids: Sequence[str],
    seeds: int,
    first_seed: int,
    hyperparams: Any,
    env_kwargs: Any,
    timesteps: int | None,
    time_budget_s: float | None,
    **run_options: Any,
) -> list[RunSpec]:
    """The runs of recipes (from ``algos`` and ``recipe_file``, filtered by ``only``) x
    ``env_ids`` x seeds; ``run_options``: :func:`~.grid.build_grid`'s evaluation options."""
    recipes = []
    if algos:
        recipes += recipes_from_algos(list(algos), hyperparams, env_kwargs, timesteps,
                                      time_budget_s)  # fmt: skip
    if recipe_file:
        recipes += load_recipes(recipe_file)
    if only:
        unknown = sorted(set(only) - {r.name for r in recipes})
        if unknown:
            raise ValueError(f"--only: no recipe named {unknown} (known: "
                             f"{sorted(r.name for r in recipes)})")  # fmt: skip
        recipes = [r for r in recipes if r.name in only]
    if seeds < 1 or first_seed < 0:
        raise ValueError(f"--seeds must be >= 1 and --first-seed >= 0, got {seeds}, "
                         f"{first_seed}")  # fmt: skip
    return build_grid(recipes, list(env_ids), list(range(first_seed, first_seed + seeds)),
                      **run_options)  # fmt: skip


def pending_runs(
    grid: Sequence[RunSpec], root: Path, retry_failed: bool
) -> tuple[list[RunSpec], list[RunSpec], list[RunSpec]]:
    """``(finished, failed_before, todo)``: runs done before, failed before, and to run now."""
    finished = [s for s in grid if (s.folder(root) / RESULT_FILE).is_file()]
    failed_before = [s for s in grid if s not in finished
                     and (s.folder(root) / FAILED_FILE).is_file()]  # fmt: skip
    todo = [s for s in grid if s not in finished and (retry_failed or s not in failed_before)]
    return finished, failed_before, todo


def run_grid(
    todo: Sequence[RunSpec],
    backend: Any,
    root: Path,
    on_start: Callable[[str], None],
    on_outcome: Callable[[dict[str, Any], Path], None],
    on_elsewhere: Callable[[str], None],
) -> list[str]:
    """Run ``todo`` on ``backend``, writing each outcome; the ids of the runs left to another
    benchmark on this folder (running or finished there). The callbacks say what happened."""
    folders = {spec.run_id: spec.folder(root) for spec in todo}
    claims, elsewhere = RunClaims(), []

    def claim(spec: dict[str, Any]) -> bool:
        """Another benchmark on this folder may hold the run, or have finished it."""
        folder = folders[spec["run_id"]]
        if claims.claim(folder) and not (folder / RESULT_FILE).is_file():
            return True
        claims.release(folder)
        elsewhere.append(spec["run_id"])
        on_elsewhere(spec["run_id"])
        return False

    try:
        outcomes = backend.run([s.to_dict() for s in todo], on_start=on_start, claim=claim)
        for outcome in outcomes:
            folder = folders[outcome["run_id"]]
            write_outcome(outcome, folder)
            claims.release(folder)
            on_outcome(outcome, folder)
    finally:
        claims.release_all()
    return elsewhere


def collect_results(
    grid: Sequence[RunSpec], root: Path
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """``(results, failed)``: the ``result.json`` and ``failed.json`` of the grid's runs, each
    checked (:func:`~baselines.benchmark.results.read_record`: a ValueError naming the file)."""
    def read(name: str, finished: bool) -> list[dict[str, Any]]:
        paths = [(s, s.folder(root) / name) for s in grid]
        return [read_record(p, s, finished=finished) for s, p in paths if p.is_file()]

    return read(RESULT_FILE, True), read(FAILED_FILE, False)


def report(
    grid: Sequence[RunSpec], root: Path, meta: dict[str, Any], plots: bool
) -> tuple[list[Path], int]:
    """Write the leaderboard of the grid's runs; the files written and how many runs failed.
    Records are read and the board written under the folder's report lock (another benchmark
    on the same ``root`` may be reporting)."""
    with report_lock(root):
        results, failed = collect_results(grid, root)
        meta = {**meta, "runs": len(grid), "finished": len(results), "failed": len(failed)}
        written = write_report(aggregate_runs(results, failed), results, meta, root, plots=plots)
    return written, len(failed)
