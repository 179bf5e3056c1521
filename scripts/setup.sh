#!/usr/bin/env bash
# Create .venv (if missing) and install the project with its rl, ray, dev, minari and docs extras
# (the benchmark tests start a real local Ray instance), at the tested versions of
# constraints.txt (pyproject.toml keeps ranges for other environments).
# torch is pinned to 2.13.0: the only build that installs here without gigabytes of CUDA wheels.
set -euo pipefail
cd "$(dirname "$0")/.."
step() { printf '\n[setup %s] %s\n' "$(date +%H:%M:%S)" "$*"; }
step "1/3 virtual environment .venv ($(python3 --version))"
python3 -m venv .venv
step "2/3 pip itself (the version the set-up was last tested with)"
.venv/bin/python -m pip install --progress-bar on "pip==26.3"
step "3/3 the project and its extras rl, ray, dev, minari, docs (pinned by constraints.txt; a few minutes)"
.venv/bin/python -m pip install --progress-bar on -c constraints.txt \
    "torch==2.13.0" -e ".[rl,ray,dev,minari,docs]"
step "done: run commands as .venv/bin/sgc, .venv/bin/python (or: source .venv/bin/activate)"
