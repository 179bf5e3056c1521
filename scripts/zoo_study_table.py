"""The equal-tuning study's table: one row per family from rl-zoo3's Optuna reports.

``scripts/zoo_study.sh`` runs rl-zoo3's own search (``-optimize``) for each family with the
same trials, steps per trial, pruner and evaluation; rl-zoo3 writes each study's trials to
``<out>/<algo>/report_<env>_<n>-trials-<steps>-<sampler>-<pruner>_<time>.csv`` (the
objective is its evaluation callback's mean episode reward, the env's own reward, on its own
evaluation seeds). This reads the newest report of every family and prints a Markdown table;
with ``--episodes N`` it also scores the best trial's model
(``<out>/<algo>/trials/trial_<n>/best_model.zip``) with the harness on held-out reset seeds
(``--seed`` onwards, which no trial saw), because the reward saturates before the goals do::

    scripts/zoo_study.sh && python scripts/zoo_study_table.py runs/zoo-study --episodes 50

Read as text through the project's bounded reader (a report may come from elsewhere); the
``.pkl`` beside each report is never opened.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from baselines.zoo.manifest import held_out_result
from sgc_env.scenario.bounded import escaped, read_text

_REPORT = re.compile(r"report_(?P<env>[^_]+)_(?P<trials>\d+)-trials-(?P<steps>\d+)"
                     r"-(?P<sampler>\w+?)-(?P<pruner>\w+?)_(?P<time>\d+)\.csv")  # fmt: skip
_SHOWN = ("gamma", "learning_rate", "batch_size", "n_steps", "n_epochs", "train_freq", "tau",
          "net_arch", "noise_type", "noise_std")  # fmt: skip


def _number(text: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}: {escaped(repr(text), 40)} is not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}: {value} is not finite")
    return value


def _short(text: str) -> str:
    """A setting as read: numbers to 3 significant digits, words escaped."""
    try:
        return f"{float(text):.3g}"
    except ValueError:
        return escaped(text, 40)


def _trial_number(text: Any, where: str) -> int:
    """A trial's number as an int: it names a folder, so a report cannot choose the path."""
    if not (isinstance(text, str) and text.isdecimal() and len(text) <= 9):
        raise ValueError(f"{where}: trial number {escaped(repr(text), 40)} is not a count")
    return int(text)


def newest_report(folder: Path) -> tuple[Path, dict[str, str]]:
    """The newest ``report_*.csv`` of one family's folder and the fields of its name."""
    found = [(m, p) for p in folder.glob("report_*.csv") if (m := _REPORT.fullmatch(p.name))]
    if not found:
        raise ValueError(f"{escaped(folder)}: no rl-zoo3 report_*.csv (run scripts/zoo_study.sh)")
    match, path = max(found, key=lambda item: int(item[0]["time"]))
    return path, match.groupdict()


def study_row(folder: Path) -> dict[str, Any]:
    """One family's study: trials by state, the objective's best and median, the best trial's
    settings and the study's seconds."""
    path, name = newest_report(folder)
    rows = list(csv.DictReader(read_text(path, "study report").splitlines()))
    where = f"study report {escaped(path)}"
    if not rows or "value" not in rows[0] or "state" not in rows[0]:
        raise ValueError(f"{where}: expected rl-zoo3's columns 'value' and 'state'")
    done = [r for r in rows if r["state"] == "COMPLETE"]
    values = [_number(r["value"], f"{where}: trial {r.get('number')}") for r in done]
    if not values:
        raise ValueError(f"{where}: no completed trial")
    best = done[int(np.argmax(values))]
    settings = {}
    for key in _SHOWN:
        value = best.get(f"user_attrs_{key}") or best.get(f"params_{key}")
        if value not in (None, ""):
            settings[key] = _short(value)
    seconds = 0.0
    for r in rows:
        duration = r.get("duration", "")
        if duration.startswith("0 days "):  # pandas' Timedelta text: "0 days 00:01:23.4"
            h, m, s = duration[len("0 days "):].split(":")
            seconds += 3600 * int(h) + 60 * int(m) + float(s)
    return {
        "algo": folder.name, "env": name["env"], "trials": len(rows),
        "steps_per_trial": int(name["steps"]), "sampler": name["sampler"],
        "pruner": name["pruner"], "complete": len(done),
        "pruned": sum(r["state"] == "PRUNED" for r in rows),
        "failed": sum(r["state"] == "FAIL" for r in rows),
        "best": max(values), "median": float(np.median(values)),
        "best_trial": _trial_number(best.get("number"), where),
        "settings": settings, "seconds": round(seconds),
    }  # fmt: skip


def score_best(row: dict[str, Any], folder: Path, episodes: int, seed: int) -> None:
    """Add the held-out goals of the best trial's model to ``row``."""
    model = folder / "trials" / f"trial_{row['best_trial']}" / "best_model.zip"
    if not model.is_file():
        raise ValueError(f"{escaped(model)}: no model of the best trial (run the study with "
                         "--optimization-log-path, as scripts/zoo_study.sh does)")  # fmt: skip
    result = held_out_result(model, row["env"], episodes, seed)
    row["held_out"] = {"goals_met": result["goals_met"], "n_goals": result["n_goals"],
                       "episodes": episodes, "seed": seed}  # fmt: skip


def markdown(rows: list[dict[str, Any]]) -> str:
    scored = all("held_out" in r for r in rows)
    lines = ["| family | env | trials (complete / pruned / failed) | steps per trial | best "
             "reward | median reward | best trial's settings | study seconds |"
             + (" best trial's held-out goals |" if scored else ""),
             "|---|---|---|---|---|---|---|---|" + ("---|" if scored else "")]  # fmt: skip
    for r in rows:
        settings = ", ".join(f"{k} {v}" for k, v in r["settings"].items())
        counts = f"{r['trials']} ({r['complete']} / {r['pruned']} / {r['failed']})"
        lines.append(f"| {r['algo'].upper()} | {r['env']} | {counts} | "
                     f"{r['steps_per_trial']:,} | {r['best']:.1f} | {r['median']:.1f} | "
                     f"{settings} | {r['seconds']} |")  # fmt: skip
        if scored:
            held = r["held_out"]
            lines[-1] += f" {held['goals_met']}/{held['n_goals']} |"
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", type=Path, help="the study's folder (scripts/zoo_study.sh's OUT)")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON")
    parser.add_argument("--episodes", type=int, default=0,
                        help="score each best trial's model on this many held-out episodes")
    parser.add_argument("--seed", type=int, default=20_000, help="first held-out reset seed")
    args = parser.parse_args()
    folders = sorted(p for p in args.out.iterdir() if p.is_dir() and any(p.glob("report_*.csv")))
    if not folders:
        raise SystemExit(f"{escaped(args.out)}: no family folder with a report_*.csv")
    rows = []
    for folder in folders:
        rows.append(study_row(folder))
        if args.episodes > 0:
            score_best(rows[-1], folder, args.episodes, args.seed)
    print(markdown(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
