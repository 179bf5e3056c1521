"""``sgc benchmark``: train a grid of recipes x env ids x seeds and report IQMs with CIs.

Modules, one job each: :mod:`.grid` (recipes, runs, argument checks), :mod:`.execute` (one
run: train, score best and final model), :mod:`.backends` (local process pool, Ray),
:mod:`.aggregate` (IQM, mean, stratified bootstrap CIs, performance profiles),
:mod:`.report` (leaderboard.md/json, plots) and :mod:`.manifest` (shipped models).
"""

from __future__ import annotations

__all__: list[str] = []
