#!/usr/bin/env bash
# Equal tuning effort per family: rl-zoo3's own Optuna search (`-optimize`, its stock samplers)
# for PPO, SAC and TD3 on SGCPoint-v1, each with the same number of trials, the same env steps
# per trial, the same pruner and evaluation, from the family's file in benchmarks/zoo with 8
# sub-envs (the samplers' rollout and batch ranges assume a handful; at 64 one PPO rollout of
# n_steps 4096 is 262k steps). Tuning seed 9001: not a leaderboard training seed (0-9) and its
# evaluations (rl-zoo3 evaluates on its own env seeds) are not the held-out seeds 20000+.
# Each study's trials go to a journal file, so a rerun resumes it; reports (CSV) land in
# $OUT/<algo>/report_*.csv, each trial's best model (by its evaluations) to
# $OUT/<algo>/trials/trial_<n>/best_model.zip; `scripts/zoo_study_table.py $OUT` tabulates them.
#   scripts/zoo_study.sh                 # ppo sac td3, 10 trials x 50k steps each
#   ALGOS="sac" TRIALS=4 scripts/zoo_study.sh
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-runs/zoo-study}
ALGOS=${ALGOS:-ppo sac td3}
TRIALS=${TRIALS:-10}
STEPS=${STEPS:-50000}
ENV_ID=${ENV_ID:-SGCPoint-v1}
PYTHON=${PYTHON:-.venv/bin/python}
for algo in $ALGOS; do
    OMP_NUM_THREADS=1 "$PYTHON" -m rl_zoo3.train --algo "$algo" --env "$ENV_ID" \
        --gym-packages sgc_env --conf-file "benchmarks/zoo/$algo.yml" --hyperparams n_envs:8 \
        -optimize --n-trials "$TRIALS" --n-startup-trials 4 --n-timesteps "$STEPS" \
        --n-evaluations 2 --eval-episodes 5 --sampler tpe --pruner median --seed 9001 \
        --num-threads 1 --no-optim-plots --storage "$OUT/$algo/study.log" \
        --optimization-log-path "$OUT/$algo/trials" \
        --study-name "$algo-$ENV_ID" -f "$OUT"
done
