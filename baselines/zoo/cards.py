"""Model cards: a markdown card beside each shipped model (``baselines/checkpoints/<stem>.md``).

A card gives the env, algorithm, recipe, training seed and steps, wall clock, the held-out
results measured when the model was shipped (read from the manifest, which says where they
were measured), a fresh held-out evaluation run by the card step itself (``episodes`` from
``seed``, :func:`baselines.zoo.manifest.held_out_result`, the same harness), the command
that reproduces it, and a GIF of one episode (``docs/images/model_<stem>.gif``). ``sgc card``
and ``scripts/ship_model.py`` write them.
"""

from __future__ import annotations

import os
import platform
import re
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from baselines.models.normalization import statistics_path
from baselines.zoo.manifest import CHECKPOINTS, held_out_result, load_manifest

__all__ = ["DOCS_IMAGES", "card_markdown", "machine", "recipe", "write_model_card"]

DOCS_IMAGES = Path(__file__).resolve().parents[2] / "docs" / "images"


def machine() -> str:
    """This machine in a few words (where the card's evaluation ran)."""
    cpu = platform.processor() or platform.machine()
    return f"{platform.system()} {cpu}, {os.cpu_count()} CPUs, Python {platform.python_version()}"


def recipe(entry: Mapping[str, Any]) -> str:
    """What the training command asked for, in words."""
    command = str(entry["command"])
    hyper = re.search(r"--hyperparams\s+(\S+)", command)
    if entry["demonstrations"]:
        rounds = re.search(r"--dagger-rounds\s+(\d+)", command)
        text = "behaviour cloning on expert demonstrations"
        return text + (f" + {rounds.group(1)} DAgger rounds" if rounds else "")
    name = Path(hyper.group(1)).name if hyper else f"baselines/hyperparams/{entry['algo']}.yml"
    return f"RL from scratch, hyperparameters `{name}`"


def _result_rows(result: Mapping[str, Any]) -> list[str]:
    def fmt(key: str, unit: str) -> str:
        value = result.get(key)
        return "n/a" if value is None else f"{value:.4g} {unit}"

    return [
        f"| episodes | {result['episodes']} (seeds {result['seed']} to "
        f"{result['seed'] + result['episodes'] - 1}) |",
        f"| goals met (2 cm on the goal's tick) | {result['goals_met']}/{result['n_goals']} |",
        f"| success rate | {result['success_rate']:.3f} |",
        f"| position error at goals, mean / max | {fmt('position_error_mean', 'm')} / "
        f"{fmt('position_error_max', 'm')} |",
        f"| orientation error at goals, mean | {fmt('orientation_error_mean', 'rad')} |",
        f"| episodes ended by failure | {result['terminated']} |",
    ]


def _has_json_statistics(model: Path) -> bool:
    """Whether the model's statistics, found as the loader finds them, are JSON."""
    found = statistics_path(model)
    return found is not None and found.suffix == ".json"


def card_markdown(entry: Mapping[str, Any], fresh: Mapping[str, Any], gif: str | None,
                  evaluated_on: str, eval_seconds: float) -> str:  # fmt: skip
    """The card of one manifest ``entry``; ``fresh``: the card step's own evaluation."""
    stem = str(entry["file"])[: -len(".zip")]
    env_id = entry["env_id"]
    evaluate = (f"sgc evaluate --env {env_id} --policy shipped:{stem} "
                f"--episodes {fresh['episodes']} --seed {fresh['seed']}")  # fmt: skip
    lines = [
        f"# Model card: `{stem}`",
        "",
        f"- **Env**: [`{env_id}`](../../docs/envs/{env_id}.md)",
        f"- **Algorithm**: {str(entry['algo']).upper()} (Stable-Baselines3)",
        f"- **Recipe**: {recipe(entry)}",
        f"- **Training seed**: {entry['seed']}",
        f"- **Training steps**: {entry['timesteps']:,} RL env steps"
        + (" (behaviour cloning and DAgger rollouts not counted)" if entry["demonstrations"]
           else ""),  # fmt: skip
        f"- **Wall clock**: {entry['wall_time_s']:.0f} s; machine: "
        + str(entry.get("machine") or "not recorded when it was trained (the project's shared "
              "CPU machine)"),  # fmt: skip
        f"- **File**: `{entry['file']}`"
        + (" with its `VecNormalize` statistics (JSON)"
           if _has_json_statistics(CHECKPOINTS / str(entry["file"])) else ""),  # fmt: skip
        "",
        "## Held-out results",
        "",
        f"Measured by the card step ({time.strftime('%Y-%m-%d')}, {evaluated_on}, "
        f"{eval_seconds:.0f} s wall), with the harness of `sgc evaluate`:",
        "",
        "| | |",
        "|---|---|",
        *_result_rows(fresh),
        "",
        "Measured when the model was shipped (read from `manifest.json`, where "
        "`scripts/ship_model.py` recorded them):",
        "",
        "| | |",
        "|---|---|",
        *_result_rows(entry["result"]),
        "",
        "## Reproduce",
        "",
        "Evaluate (the card's own run):",
        "",
        "```bash",
        evaluate,
        "```",
        "",
        "Train (the recorded command):",
        "",
        "```bash",
        str(entry["command"]),
        "```",
    ]
    if gif is not None:
        lines += ["", "## One episode", "", f"![{stem} on {env_id}, seed {fresh['seed']}]({gif})"]
    return "\n".join(lines) + "\n"


def write_model_card(entry: Mapping[str, Any], *, episodes: int = 10, seed: int | None = None,
                     gif: bool = True, folder: Path = CHECKPOINTS) -> Path:  # fmt: skip
    """Evaluate the model of ``entry`` on ``episodes`` held-out seeds from ``seed`` (default:
    the manifest result's first seed), draw its GIF (``gif=False`` keeps an existing one) and
    write ``<stem>.md`` beside it."""
    from baselines.figures.episode_gif import episode_gif

    if episodes < 1:
        raise ValueError(f"episodes: expected a positive integer, got {episodes!r}")
    stem = str(entry["file"])[: -len(".zip")]
    model = folder / str(entry["file"])
    if not model.is_file():
        raise ValueError(f"model card: no {model}")
    first = int(entry["result"]["seed"]) if seed is None else seed
    started = time.perf_counter()
    fresh = held_out_result(model, entry["env_id"], episodes, first)
    seconds = time.perf_counter() - started
    path = DOCS_IMAGES / f"model_{stem}.gif"
    if gif:
        episode_gif(entry["env_id"], str(model), path, seed=first, fps=8.0)
    link = os.path.relpath(path, folder) if path.is_file() else None
    card = folder / f"{stem}.md"
    card.write_text(card_markdown(entry, fresh, link, machine(), seconds))
    return card


def entries(stems: list[str] | None = None) -> list[dict[str, Any]]:
    """Manifest entries, all or those whose file stem is in ``stems`` (else a ValueError)."""
    found = load_manifest()
    if not stems:
        return found
    known = {str(e["file"])[: -len(".zip")]: e for e in found}
    missing = [s for s in stems if s not in known]
    if missing:
        raise ValueError(f"model: no shipped model {missing}; shipped: {sorted(known)}")
    return [known[s] for s in stems]
