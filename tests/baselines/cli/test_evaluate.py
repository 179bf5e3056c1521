"""``sgc evaluate`` and ``sgc rollout`` through the console entry point."""

from __future__ import annotations

import csv
import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from baselines.cli import main as cli
from baselines.evaluation.harness import GOAL_COLUMNS

SHIPPED = Path(__file__).resolve().parents[3] / "baselines" / "checkpoints"


@pytest.fixture(autouse=True)
def _importable_commands(monkeypatch):
    """Build the parser from the commands that exist (others are written concurrently)."""
    present = {
        name: text
        for name, text in cli.COMMANDS.items()
        if importlib.util.find_spec(f"baselines.cli.commands.{name.replace('-', '_')}") is not None
    }
    monkeypatch.setattr(cli, "COMMANDS", present)


def test_evaluate_writes_table_files_and_plots(tmp_path, capsys):
    out = tmp_path / "ev"
    argv = ["evaluate", "--env", "SGCPoint-v1", "--policy", "expert", "--episodes", "1"]
    assert cli.main([*argv, "--seed", "7", "--out", str(out)]) == 0
    with (out / "goals.csv").open() as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == GOAL_COLUMNS
        rows = list(reader)
    assert rows and all(float(r["position_error"]) <= 1e-8 for r in rows)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["episodes"] == 1 and summary["seed"] == 7
    assert (out / "goal_errors.png").stat().st_size > 0
    assert (out / "speed_profile.png").stat().st_size > 0
    assert "SGCPoint-v1" in capsys.readouterr().out


def test_evaluate_compares_policies(tmp_path, capsys):
    out = tmp_path / "cmp"
    argv = ["evaluate", "--env", "SGCPoint-v1", "--policy", "expert,random", "--policy"]
    assert (
        cli.main([*argv, "minimum-jerk", "--episodes", "1", "--no-plots", "--out", str(out)]) == 0
    )
    cards = json.loads((out / "scorecard.json").read_text())
    assert [c["policy"] for c in cards] == ["expert", "random", "minimum-jerk"]
    table = (out / "scorecard.md").read_text()
    assert table.count("\n") == 2 + 3 and "| SGCPoint-v1 | random |" in table
    for name in ("expert", "random", "minimum-jerk"):
        assert (out / "SGCPoint-v1" / name / "goals.csv").is_file()
    assert "random" in capsys.readouterr().out


def test_evaluate_reports_bad_arguments(tmp_path, capsys):
    argv = ["evaluate", "--policy", "nope", "--episodes", "1", "--out", str(tmp_path)]
    assert cli.main(argv) == 2
    assert "unknown spec 'nope'" in capsys.readouterr().err
    assert cli.main(["evaluate", "--env", "Nope-v0", "--out", str(tmp_path)]) == 2
    assert cli.main(["evaluate", "--episodes", "0", "--out", str(tmp_path)]) == 2


def test_evaluate_keeps_models_with_the_same_file_name_apart(tmp_path, capsys):
    shipped = SHIPPED / "ppo_dagger_SGCPoint-v1.zip"
    specs = []
    for run in ("run_a", "run_b"):
        (tmp_path / run).mkdir()
        specs.append(str(tmp_path / run / "final_model.zip"))
        shutil.copy(shipped, specs[-1])
    out = tmp_path / "cmp"
    argv = ["evaluate", "--env", "SGCPoint-v1", "--policy", ",".join(specs), "--episodes", "1"]
    assert cli.main([*argv, "--no-plots", "--out", str(out)]) == 0
    cards = json.loads((out / "scorecard.json").read_text())
    assert [c["policy"] for c in cards] == ["run_a-final_model", "run_b-final_model"]
    for label in ("run_a-final_model", "run_b-final_model"):
        assert (out / "SGCPoint-v1" / label / "goals.csv").is_file()
    assert cli.main([*argv[:4], f"{specs[0]},{specs[0]}", "--out", str(out)]) == 2
    assert "given more than once" in capsys.readouterr().err


def test_rollout_writes_trajectory_and_figures(tmp_path):
    out = tmp_path / "ro"
    assert cli.main(["rollout", "--scenario", "point_three_goals", "--out", str(out)]) == 0
    data = np.load(out / "trajectory.npz")
    assert data["time"][0] == 0.0 and data["point_position"].shape[1:] == (1, 3)
    assert data["goal_times_0"].shape == (3,)
    for name in ("deviation.png", "path3d.png", "speed.png", "figure1_vs_2.png"):
        assert (out / name).stat().st_size > 0
    assert json.loads((out / "summary.json").read_text())["success_rate"] == 1.0


def test_rollout_from_env_seed_with_another_controller(tmp_path):
    out = tmp_path / "ro2"
    argv = ["rollout", "--env", "SGCRod-v1", "--seed", "4", "--policy", "minimum-jerk"]
    assert cli.main([*argv, "--no-compare", "--out", str(out)]) == 0
    assert not (out / "figure1_vs_2.png").exists()
    assert (out / "deviation.png").is_file()
    assert not (out / "rollout.glb").exists()  # only when asked


def test_rollout_writes_the_motion_as_gltf_when_asked(tmp_path):
    from tests.sgc_env.export.glb_reader import read_glb

    out = tmp_path / "ro3"
    argv = ["rollout", "--env", "SGCRod-v1", "--seed", "4", "--gltf", "--no-compare"]
    assert cli.main([*argv, "--out", str(out)]) == 0
    glb = read_glb(out / "rollout.glb")
    data = np.load(out / "trajectory.npz")
    node = glb.node_index("expert/body0")  # the random family names its one body body0
    times, translations = glb.keyframes("expert", node, "translation")
    np.testing.assert_allclose(times, data["time"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(translations, data["body_position"][:, 0], rtol=0, atol=1e-6)
    assert (out / "viewer.html").is_file()


@pytest.mark.slow
def test_rollout_video(tmp_path):
    out = tmp_path / "vid"
    argv = ["rollout", "--scenario", "point_three_goals", "--video", "--no-compare"]
    assert cli.main([*argv, "--out", str(out)]) == 0
    assert (out / "rollout.mp4").stat().st_size > 1000
