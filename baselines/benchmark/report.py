"""The benchmark's outputs: ``leaderboard.json``, ``leaderboard.md`` and the plots.

The markdown has one table per env id, one row per recipe: seeds, the wall-clock budget per
run (``–``: none), the steps reached (median [min, max] over seeds: under a budget they vary),
the seconds of training, their CPU share (CPU seconds of the run's process / wall seconds:
below ~0.9 the run shared its core), the whole run's wall clock (scoring included), and for
the final and the best model the goal-met rate and the main harness metrics as IQM [95 % CI]
over seeds (the mean and every other metric are in the JSON).
The command that reproduces the whole table heads the file.
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from baselines.benchmark.aggregate import (
    CONFIDENCE,
    CURVE_AXES,
    learning_curve,
    performance_profile,
)
from baselines.common.atomic_files import write_atomic

__all__ = ["format_ci", "markdown", "write_report"]

#: (model, metric, title, format) of the markdown columns after the run columns.
COLUMNS: tuple[tuple[str, str, str, str], ...] = (
    ("final", "success_rate", "goals met, final: IQM [CI]", ".2f"),
    ("final", "success_rate|mean", "goals met, final: mean [CI]", ".2f"),
    ("best", "success_rate", "goals met, best: IQM [CI]", ".2f"),
    ("final", "position_error_mean", "pos err mean (m), final", ".3f"),
    ("final", "position_closest_offset_abs_max", "closest offset max (s), final", ".3f"),
    ("final", "sparc_track_mean", "SPARC track, final", ".2f"),
    ("final", "acceleration_kink_max", "kink (m/s²), final", ".1f"),
    ("final", "angular_acceleration_kink_max", "ang kink (rad/s²), final", ".1f"),
)


def format_ci(stats: Mapping[str, Any], fmt: str, which: str = "iqm") -> str:
    """``0.42 [0.30, 0.55]`` (``–`` when there is no finite value)."""
    value, ci = stats.get(which), stats.get(f"{which}_ci")
    if value is None or not math.isfinite(value):
        return "–"
    if ci is None:
        return format(value, fmt)
    return f"{value:{fmt}} [{ci[0]:{fmt}}, {ci[1]:{fmt}}]"


def _per_run(values: Sequence[float], fmt: str) -> str:
    return format(float(np.mean(values)), fmt) if values else "–"


def _median_range(values: Sequence[float | None], fmt: str) -> str:
    """``median [min, max]`` over seeds (``–`` when no run has the value)."""
    known = [float(v) for v in values if v is not None]
    if not known:
        return "–"
    median = float(np.median(known))
    if len(known) == 1:
        return format(median, fmt)
    return f"{median:{fmt}} [{min(known):{fmt}}, {max(known):{fmt}}]"


def _cell(row: Mapping[str, Any], model: str, key: str, fmt: str) -> str:
    metric, _, which = key.partition("|")
    return format_ci(row[model][metric], fmt, which or "iqm")


def markdown(rows: Sequence[Mapping[str, Any]], meta: Mapping[str, Any]) -> str:
    """The leaderboard in GitHub markdown (see the module docstring)."""
    head = ["recipe", "algo", "demos", "seeds", "budget / run (s)",
            "steps reached: median [range]", "training (s): median [range]", "CPU / wall",
            "wall / run (s)",
            *(title for *_, title, _ in COLUMNS), "failed"]  # fmt: skip
    lines = [
        "# Benchmark leaderboard",
        "",
        f"Reproduce: `{meta['command']}`",
        "",
        f"Each row: IQM (mean of the middle 50 % of seeds) with a {CONFIDENCE:.0%} stratified "
        f"percentile bootstrap CI over training seeds (Agarwal et al. 2021). Scored on "
        f"{meta['eval_episodes']} held-out episodes per run (reset seeds from "
        f"{meta['test_seed']}); 'best' is the model the learning-curve evaluations (seeds from "
        f"{meta['eval_seed']}) picked. A goal is met within 2 cm (and 0.05 rad) at its own time.",
    ]
    for env_id in sorted({r["env_id"] for r in rows}):
        lines += ["", f"## {env_id}", "", "| " + " | ".join(head) + " |",
                  "|" + "|".join("---" for _ in head) + "|"]  # fmt: skip
        for row in (r for r in rows if r["env_id"] == env_id):
            cells = [
                row["recipe"], row["algo"], "yes" if row["demonstrations"] else "no",
                str(len(row["seeds"])), _budget(row.get("time_budget_s")),
                _median_range(row["timesteps"], ",.0f"),
                _median_range(row.get("train_time_s", []), ",.0f"),
                _cpu_share(row),
                _per_run(row["wall_time_s"], ",.0f"),
                *(_cell(row, model, key, fmt) for model, key, _, fmt in COLUMNS),
                str(len(row["failed_seeds"])),
            ]  # fmt: skip
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _cpu_share(row: Mapping[str, Any]) -> str:
    """Median over seeds of CPU seconds / wall seconds of training: below ~0.9 the run shared
    its core, and a time budget then bought fewer steps than the machine gives alone."""
    pairs = [(c, w) for c, w in zip(row.get("train_cpu_s", []), row.get("train_time_s", []),
                                    strict=False) if c is not None and w]  # fmt: skip
    return format(float(np.median([c / w for c, w in pairs])), ".2f") if pairs else "–"


def _budget(seconds: float | None) -> str:
    return "–" if seconds is None else format(seconds, "g")


#: x-axis label and title of each learning-curve panel.
_AXIS_LABELS = {"timesteps": ("env steps (median over seeds, bar: range)", "against steps"),
                "train_time_s": ("seconds of training (median over seeds, bar: range)",
                                 "against wall clock")}  # fmt: skip


def _plot_profiles(rows: Sequence[Mapping[str, Any]], runs: Sequence[Mapping[str, Any]],
                   out: Path) -> list[Path]:  # fmt: skip
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    taus = np.linspace(0.0, 1.0, 51)
    for env_id in sorted({r["env_id"] for r in rows}):
        fig, (ax_p, *ax_curves) = plt.subplots(1, 3, figsize=(16, 4))
        for row in (r for r in rows if r["env_id"] == env_id and r["seeds"]):
            mine = [r for r in runs if r["spec"]["env_id"] == env_id
                    and r["spec"]["recipe"]["name"] == row["recipe"]]  # fmt: skip
            scores = [r["scores"]["final"].get("success_rate") or 0.0 for r in mine]
            prof = performance_profile([scores], [float(t) for t in taus])
            (line,) = ax_p.plot(prof["tau"], prof["fraction"], label=row["recipe"])
            ax_p.fill_between(prof["tau"], prof["low"], prof["high"], alpha=0.2,
                              color=line.get_color())  # fmt: skip
            for axis, ax_c in zip(CURVE_AXES, ax_curves, strict=True):
                curve = learning_curve(mine, axis=axis)
                if curve[axis]:
                    ax_c.plot(curve[axis], curve["iqm"], color=line.get_color(), marker="o",
                              label=row["recipe"])  # fmt: skip
                    ax_c.fill_between(curve[axis], curve["low"], curve["high"], alpha=0.2,
                                      color=line.get_color())  # fmt: skip
                    lo, hi = zip(*curve[f"{axis}_range"], strict=True)  # seeds' spread in x
                    ax_c.hlines(curve["iqm"], lo, hi, color=line.get_color(), alpha=0.5)
        ax_p.set(xlabel="goal-met rate tau (final model)", ylabel="fraction of runs > tau",
                 title=f"{env_id}: performance profile", ylim=(-0.02, 1.02))  # fmt: skip
        for axis, ax_c in zip(CURVE_AXES, ax_curves, strict=True):
            label, title = _AXIS_LABELS[axis]
            ax_c.set(xlabel=label, ylabel="goal-met rate (IQM over seeds)",
                     title=f"{env_id}: learning curves {title}", ylim=(-0.02, 1.02))  # fmt: skip
        for ax in (ax_p, *ax_curves):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        fig.tight_layout()
        path = out / f"{env_id}.png"
        image = io.BytesIO()
        fig.savefig(image, format="png", dpi=110)
        plt.close(fig)
        write_atomic(path, image.getvalue())
        written.append(path)
    return written


def write_report(
    rows: Sequence[Mapping[str, Any]],
    runs: Sequence[Mapping[str, Any]],
    meta: Mapping[str, Any],
    out: str | Path,
    plots: bool = True,
) -> list[Path]:
    """Write ``leaderboard.json``, ``leaderboard.md`` and (``plots``) one PNG per env, each
    atomically (two benchmarks on one folder: the last to finish wins, whole)."""
    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)
    curves = {}
    for r in rows:
        mine = [x for x in runs if x["spec"]["env_id"] == r["env_id"]
                and x["spec"]["recipe"]["name"] == r["recipe"]]  # fmt: skip
        curves[f"{r['env_id']}/{r['recipe']}"] = {
            **learning_curve(mine), "wall_clock": learning_curve(mine, axis="train_time_s")
        }
    data = {"meta": dict(meta), "rows": list(rows), "learning_curves": curves}
    json_path = write_atomic(root / "leaderboard.json",
                             json.dumps(data, indent=1, allow_nan=False) + "\n")  # fmt: skip
    md_path = write_atomic(root / "leaderboard.md", markdown(rows, meta))
    written = [json_path, md_path]
    if plots:
        written += _plot_profiles(rows, runs, root)
    return written
