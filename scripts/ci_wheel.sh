#!/usr/bin/env bash
# Build the wheel, install it into a fresh venv outside the checkout (torch==2.13.0, the rl
# extra, constraints.txt), then train and evaluate from another directory: package data
# (hyperparameters, scenarios, shipped models) must come from the wheel, not the checkout; and
# time one env against the bare PyBullet loop (sgc bench), as a user comparing machines does.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
work="$(mktemp -d "${TMPDIR:-/tmp}/sgc-wheel.XXXXXX")"
trap 'rm -rf "$work"' EXIT
step() { printf '\n[wheel %s] %s\n' "$(date +%H:%M:%S)" "$*"; }
step "1/4 build the wheel (from a copy of the tracked and unignored files: no build/ left here)"
mkdir "$work/src"
git ls-files -z --cached --others --exclude-standard | xargs -0 cp --parents -t "$work/src"
.venv/bin/python -m pip wheel --no-deps --progress-bar off -w "$work/dist" "$work/src" >/dev/null
wheel="$(ls "$work"/dist/sgc-*.whl)"
unzip -l "$wheel" | grep -E "hyperparams/ppo.yml|scenario/builtin/three_rods.yaml|ppo_dagger_SGCPoint-v1.(zip|md)|export/viewer.html"
cards="$(unzip -l "$wheel" | grep -c "baselines/checkpoints/.*\.md$")"
test "$cards" -eq "$(ls baselines/checkpoints/*.md | wc -l)"  # every shipped model's card
step "2/4 install $(basename "$wheel")[rl] into a fresh venv"
python3 -m venv "$work/venv"
# --no-compile: modules compile on first import instead (saves compiling all of torch)
"$work/venv/bin/python" -m pip install --progress-bar off -q --no-compile \
    -c "$root/constraints.txt" "torch==2.13.0" "${wheel}[rl]"
mkdir "$work/elsewhere" && cd "$work/elsewhere"
"$work/venv/bin/python" - <<'PY'
import baselines, sgc_env
assert "site-packages" in baselines.__file__ and "site-packages" in sgc_env.__file__, (
    baselines.__file__, sgc_env.__file__)
print("imports from", baselines.__file__)
PY
step "3/4 sgc train (one PPO rollout) from $PWD"
"$work/venv/bin/sgc" train --algo ppo --env SGCPoint-v1 --timesteps 2048 --out train
step "4/4 sgc evaluate: the expert and the shipped model of the point (a clone)"
"$work/venv/bin/sgc" evaluate --env SGCPoint-v1 --policy expert,shipped:SGCPoint-v1 \
    --episodes 2 --no-plots --out evaluate
test -s evaluate/scorecard.md && test -s train/final_model.zip
"$work/venv/bin/sgc" demo --no-video --out demo  # the glTF file and its viewer page, from the wheel
test -s demo/three_rods.glb && grep -q GLTFLoader demo/viewer.html
# a timing comparison from the wheel: the env against the bare loop of its physics
"$work/venv/bin/sgc" bench env --ids SGCPoint-v1 --steps 200 --resets 10 --rounds 2 --draws 2 \
    | tee bench.txt
grep -q "^SGCPoint-v1 " bench.txt
step "wheel check passed"
