#!/usr/bin/env bash
# The three-rod learner's rows (docs/results.md, "The learned three-rod agent"): one shared net
# per body on the env's own learner view and reward, plain (ppo-perbody) and with CAPS's
# smoothness terms (ppo-perbody-caps), SEEDS training seeds each, one run per core, scored on
# 50 held-out random scenes per run (reset seeds 20000+), goals and kinks side by side.
# Resumable: rerun and the finished runs are skipped; --report-only writes the leaderboard
# from the runs so far. Extra arguments go to `sgc benchmark`.
#   scripts/run_threerod_rows.sh                        # both rows, 5 seeds (about 2 h on 2 cores)
#   ROWS=ppo-perbody-caps scripts/run_threerod_rows.sh
# Environment: OUT (runs/benchmark/threerod), ROWS, SEEDS (5), WORKERS (2), SGC (.venv/bin/sgc).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-runs/benchmark/threerod}
ROWS=${ROWS:-ppo-perbody-caps,ppo-perbody}
SEEDS=${SEEDS:-5}
WORKERS=${WORKERS:-2}
SGC=${SGC:-.venv/bin/sgc}
exec "$SGC" benchmark --recipes benchmarks/recipes.yml --only "$ROWS" \
    --env SGCThreeRodsRandom-v3 --seeds "$SEEDS" --eval-episodes 50 \
    --workers "$WORKERS" --out "$OUT" "$@"
