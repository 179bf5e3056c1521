#!/usr/bin/env bash
# The equal wall-clock leaderboard (docs/results.md; budgets explained in docs/agents.md): every budget
# recipe of benchmarks/recipes.yml x 10 training seeds, one run per core (--workers 2 on the
# 2-core machine; torch uses one thread per run). Resumable: rerun the same command and the
# finished runs are skipped; with --report-only it runs nothing and writes the leaderboard
# from the runs finished so far. Extra arguments go to `sgc benchmark`.
#   scripts/run_budget_rows.sh                 # everything (18,000 s of training: about 3 h on 2 quiet cores)
#   scripts/run_budget_rows.sh --report-only   # the leaderboard so far
# Environment: OUT (runs/benchmark/budget), SEEDS (10), WORKERS (2), SGC (.venv/bin/sgc), ROWS
# (a comma list of those recipes; default: all).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-runs/benchmark/budget}
SEEDS=${SEEDS:-10}
WORKERS=${WORKERS:-2}
SGC=${SGC:-.venv/bin/sgc}
# keep in step with the budget recipes of benchmarks/recipes.yml (tests/baselines/agents/test_budget.py checks)
ALL=zoo-ppo-300s,zoo-sac-300s,zoo-td3-300s,bc-dagger-300s
ALL=$ALL,zoo-ppo-120s,zoo-sac-120s,zoo-td3-120s,zoo-her-120s,bc-dagger-120s
ROWS=${ROWS:-$ALL}
if [[ " $* " != *" --report-only "* ]]; then
    for env in SGCPoint-v1 SGCRod-v1; do  # the BC+DAgger rows' demonstrations (not timed)
        demos=runs/benchmark-demos/${env}_100.npz
        [[ -f $demos ]] || "$SGC" demos --env "$env" --episodes 100 --seed 0 --out "$demos"
    done
fi
exec "$SGC" benchmark --recipes benchmarks/recipes.yml --only "$ROWS" \
    --env SGCPoint-v1,SGCPointGoal-v1,SGCRod-v1 --seeds "$SEEDS" --eval-episodes 50 \
    --workers "$WORKERS" --out "$OUT" "$@"
