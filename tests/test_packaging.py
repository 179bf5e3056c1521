"""Package data is found through importlib.resources, so a wheel works outside the checkout.

The wheel itself is built, installed into a fresh venv and run from another directory by
``scripts/ci_wheel.sh`` (a CI step); these tests check the look-ups it relies on.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import pytest

import sgc_env
from baselines.agents.hyperparams import load_hyperparams
from baselines.common.shipped import (
    hyperparams_file,
    resolve_policy_spec,
    shipped_files,
    shipped_models,
)
from baselines.policies import make_policy

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("algo", ["ppo", "sac", "td3", "her"])
def test_packaged_hyperparams_load_without_a_folder(algo: str) -> None:
    assert hyperparams_file(algo).is_file()
    env_id = "SGCPointGoal-v1" if algo == "her" else "SGCPoint-v1"
    hp = load_hyperparams(algo, env_id)
    assert hp.env_id == env_id and hp.n_timesteps > 0


def test_shipped_models_resolve_and_load() -> None:
    models = shipped_models()
    assert set(models) <= set(sgc_env.ENV_IDS) and "SGCPoint-v1" in models
    assert resolve_policy_spec("shipped:SGCPoint-v1") == models["SGCPoint-v1"]
    for stem, path in shipped_files().items():
        assert resolve_policy_spec(f"shipped:{stem}") == path
    assert "ppo_caps_SGCThreeRodsRandom-v3" in shipped_files()  # learned without demos
    assert resolve_policy_spec("expert") == "expert"
    env = gym.make("SGCPoint-v1")
    obs, _ = env.reset(seed=0)
    action, _ = make_policy("shipped:SGCPoint-v1", env).predict(obs)
    assert env.action_space.contains(action.astype(env.action_space.dtype))
    with pytest.raises(ValueError, match="no shipped model 'shipped:Nope-v0'"):
        resolve_policy_spec("shipped:Nope-v0")
    env.close()


def test_package_data_globs_cover_the_data_files() -> None:
    """Every data file under the packages is matched by a package-data glob (else the wheel
    silently lacks it)."""
    tomllib = pytest.importorskip("tomllib", reason="tomllib is in the stdlib from 3.11")
    globs = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"
    ]
    for package in ("sgc_env", "baselines"):
        data = {
            p.relative_to(ROOT / package)
            for p in (ROOT / package).rglob("*")
            if p.is_file() and p.suffix in (".yml", ".yaml", ".zip")
        }
        covered = {p for p in data if any(p.match(g) for g in globs.get(package, []))}
        assert data and covered == data, f"{package}: not shipped: {sorted(data - covered)}"
