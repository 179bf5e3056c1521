"""Statistics over training seeds as Agarwal et al. (2021) recommend: IQM, mean, bootstrap CIs.

"Deep RL at the Edge of the Statistical Precipice": report the interquartile mean (the mean
of the middle 50 % of runs, ``scipy.stats.trim_mean(x, 0.25)``) next to the mean, each with
a 95 % percentile confidence interval from a *stratified* bootstrap: runs are resampled with
replacement within each task (here an env id), never across, and the statistic is taken over
the pooled resample. Per env and recipe there is one stratum and this is the ordinary
percentile bootstrap over seeds. Performance profiles give, for each threshold tau, the
fraction of runs scoring above tau, with the same bootstrap bands.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
from scipy.stats import trim_mean

__all__ = [
    "CONFIDENCE",
    "METRICS",
    "aggregate_runs",
    "iqm",
    "CURVE_AXES",
    "learning_curve",
    "performance_profile",
    "stratified_bootstrap_ci",
    "summarize_metric",
]

CONFIDENCE = 0.95
N_RESAMPLES = 2000
#: Harness scorecard keys aggregated per env and recipe (see docs/evaluation.md).
METRICS: tuple[str, ...] = (
    "success_rate", "position_error_mean", "position_error_max", "orientation_error_mean",
    "position_closest_offset_abs_max", "sparc_track_mean", "velocity_jump_max",
    "force_sq_integral_mean", "terminated", "return_mean", "acceleration_kink_max",
    "angular_acceleration_kink_max",
)  # fmt: skip

Statistic = Callable[[np.ndarray], np.ndarray]


def iqm(values: np.ndarray, axis: int | None = None) -> Any:
    """Interquartile mean: the mean after trimming 25 % of the values at each end."""
    return trim_mean(np.asarray(values, dtype=float), 0.25, axis=axis)


def _mean(values: np.ndarray, axis: int | None = None) -> Any:
    return np.mean(np.asarray(values, dtype=float), axis=axis)


STATISTICS: dict[str, Statistic] = {"iqm": iqm, "mean": _mean}


def stratified_bootstrap_ci(
    strata: Sequence[Sequence[float]],
    statistic: Callable[..., Any] = iqm,
    *,
    confidence: float = CONFIDENCE,
    n_resamples: int = N_RESAMPLES,
    seed: int = 0,
) -> tuple[float, float]:
    """Percentile CI of ``statistic`` (called with ``axis=1``) over stratum-wise resamples.

    Each stratum (one task's runs) is resampled with replacement to its own size, the
    resamples are pooled per replicate and the statistic is taken over the pool. One run in
    every stratum gives a zero-width interval: one seed says nothing about the spread.
    """
    groups = [np.asarray(s, dtype=float) for s in strata]
    if not groups or any(g.ndim != 1 or g.size == 0 for g in groups):
        raise ValueError("strata: need one or more non-empty 1-d groups of scores")
    if any(not np.all(np.isfinite(g)) for g in groups):
        raise ValueError("strata: scores must be finite")
    if not 0 < confidence < 1 or n_resamples < 1:
        raise ValueError(f"need 0 < confidence < 1 and n_resamples >= 1, got {confidence}, "
                         f"{n_resamples}")  # fmt: skip
    rng = np.random.default_rng(seed)
    pooled = np.concatenate(
        [g[rng.integers(0, g.size, size=(n_resamples, g.size))] for g in groups], axis=1
    )
    replicates = np.asarray(statistic(pooled, axis=1), dtype=float)
    alpha = (1 - confidence) / 2
    low, high = np.quantile(replicates, [alpha, 1 - alpha])
    return float(low), float(high)


def summarize_metric(strata: Sequence[Sequence[Any]], seed: int = 0) -> dict[str, Any]:
    """IQM and mean with their CIs over the finite values (None where there are none)."""
    groups = [[float(v) for v in s if v is not None and math.isfinite(float(v))] for s in strata]
    groups = [g for g in groups if g]
    out: dict[str, Any] = {"n": sum(len(g) for g in groups)}
    for name, statistic in STATISTICS.items():
        if not groups:
            out[name], out[f"{name}_ci"] = None, None
            continue
        out[name] = float(statistic(np.concatenate(groups)))
        out[f"{name}_ci"] = list(stratified_bootstrap_ci(groups, statistic, seed=seed))
    return out


def performance_profile(
    strata: Sequence[Sequence[float]], taus: Sequence[float], seed: int = 0
) -> dict[str, list[float]]:
    """Fraction of runs scoring above each tau, with stratified bootstrap bands."""
    groups = [np.asarray(s, dtype=float) for s in strata]
    thresholds = np.asarray(taus, dtype=float)

    def profile(pool: np.ndarray, axis: int = 1) -> np.ndarray:
        return (pool[..., None] > thresholds).mean(axis=axis)

    rng = np.random.default_rng(seed)
    pooled = np.concatenate(
        [g[rng.integers(0, g.size, size=(N_RESAMPLES, g.size))] for g in groups], axis=1
    )
    replicates = profile(pooled)
    alpha = (1 - CONFIDENCE) / 2
    low, high = np.quantile(replicates, [alpha, 1 - alpha], axis=0)
    point = profile(np.concatenate(groups)[None, :])[0]
    return {"tau": thresholds.tolist(), "fraction": point.tolist(), "low": low.tolist(),
            "high": high.tolist()}  # fmt: skip


def _metric(result: Mapping[str, Any], model: str, key: str) -> Any:
    return result["scores"][model].get(key)


def aggregate_runs(
    results: Sequence[Mapping[str, Any]], failed: Sequence[Mapping[str, Any]] = ()
) -> list[dict[str, Any]]:
    """One row per (env, recipe): seeds, steps, wall time, and every metric for both models."""
    keys = sorted({(r["spec"]["env_id"], r["spec"]["recipe"]["name"]) for r in [*results, *failed]})
    rows = []
    for env_id, recipe in keys:
        runs = [r for r in results if (r["spec"]["env_id"], r["spec"]["recipe"]["name"])
                == (env_id, recipe)]  # fmt: skip
        runs.sort(key=lambda r: r["spec"]["seed"])
        bad = [f for f in failed if (f["spec"]["env_id"], f["spec"]["recipe"]["name"])
               == (env_id, recipe)]  # fmt: skip
        spec = (runs or bad)[0]["spec"]
        row: dict[str, Any] = {
            "env_id": env_id, "recipe": recipe, "algo": spec["recipe"]["algo"],
            "demonstrations": spec["recipe"]["demonstrations"],
            "seeds": [r["spec"]["seed"] for r in runs],
            "failed_seeds": sorted(f["spec"]["seed"] for f in bad),
            "eval_episodes": spec["eval_episodes"], "test_seed": spec["test_seed"],
            "timesteps": [r["timesteps"] for r in runs],
            "time_budget_s": spec["recipe"].get("time_budget_s"),
            "train_time_s": [r.get("train_time_s") for r in runs],
            "train_cpu_s": [r.get("train_cpu_s") for r in runs],
            "wall_time_s": [r["wall_time_s"] for r in runs],
            "steps_per_s": [r["steps_per_s"] for r in runs],
            "commands": [r["command"] for r in runs],
        }  # fmt: skip
        for model in ("final", "best"):
            row[model] = {
                key: summarize_metric([[_metric(r, model, key) for r in runs]]) for key in METRICS
            }
        rows.append(row)
    return rows


CURVE_AXES = ("timesteps", "train_time_s")
"""What a learning curve can be drawn against: env steps, or seconds of training."""


def learning_curve(
    runs: Sequence[Mapping[str, Any]], key: str = "success_rate", axis: str = "timesteps"
) -> dict[str, list[Any]]:
    """IQM and CI of ``key`` over seeds at each evaluation every run has.

    The k-th evaluations of all runs form the k-th point (runs of a grid evaluate on one
    schedule: every N steps, or every N seconds of training under a time budget). Its
    position on ``axis`` is the median over the runs, with their range in ``<axis>_range``:
    under a time budget the steps of the k-th point differ from seed to seed, and without one
    its seconds do. Runs without ``axis`` in their curve (older runs, for ``train_time_s``)
    give an empty curve.
    """
    if axis not in CURVE_AXES:
        raise ValueError(f"axis: expected one of {CURVE_AXES}, got {axis!r}")
    out: dict[str, list[Any]] = {axis: [], f"{axis}_range": [], "iqm": [], "low": [], "high": []}
    curves = [list(r.get("curve", [])) for r in runs]
    if not curves or any(e.get(axis) is None for c in curves for e in c):
        return out
    for k in range(min(len(c) for c in curves)):
        stats = summarize_metric([[c[k].get(key) for c in curves]])
        if stats["iqm"] is None:
            continue
        where = [float(c[k][axis]) for c in curves]
        out[axis].append(float(np.median(where)))
        out[f"{axis}_range"].append([min(where), max(where)])
        out["iqm"].append(stats["iqm"])
        out["low"].append(stats["iqm_ci"][0])
        out["high"].append(stats["iqm_ci"][1])
    return out
