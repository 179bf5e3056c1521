#!/usr/bin/env bash
# Create .venv (if missing) and install the project with its RL, Ray and dev extras
# (the benchmark tests start a real local Ray instance).
# torch is pinned to 2.13.0: the only build that installs here without gigabytes of CUDA wheels.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet "torch==2.13.0" -e ".[rl,ray,dev]"
