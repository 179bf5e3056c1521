"""``sgc benchmark``: train a grid of recipes x env ids x seeds and report IQMs with CIs.

Modules, one job each: :mod:`.grid` (recipes, runs, argument checks), :mod:`.execute` (one
run: train, score best and final model), :mod:`.backends` (local process pool, Ray),
:mod:`.claims` (a run held by one benchmark on a shared folder), :mod:`.aggregate` (IQM,
mean, stratified bootstrap CIs, performance profiles), :mod:`.report` (leaderboard.md/json,
plots) and :mod:`.driver` (all of it from the options to the leaderboard). The shipped models
are :mod:`baselines.zoo`'s.
"""

from __future__ import annotations

__all__: list[str] = []
