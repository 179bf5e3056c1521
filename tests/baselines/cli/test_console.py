"""The console at a person's terminal width: compact tables, one summary line, defaults in
``--help``, whole rollouts announced."""

from __future__ import annotations

import pytest

from baselines.agents.budget import whole_rollouts
from baselines.agents.hyperparams import load_hyperparams
from baselines.cli.console import summary_line
from baselines.cli.main import build_parser, main


def test_evaluate_fits_80_columns(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    argv = ["evaluate", "--env", "SGCIntercept-v1", "--policy", "expert,dynamic-constraints",
            "--episodes", "1", "--no-plots", "--out", str(tmp_path)]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= 80
    assert "…" not in out  # no cell cut short
    assert "dynamic-constraints" in out and "goals met: expert 2/2, dynamic-constraints" in out
    assert main([*argv, "--wide"]) == 0
    wide = capsys.readouterr().out
    assert "SPARC track" in wide and "…" not in wide


def test_single_pair_ends_with_one_summary_line(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    argv = ["evaluate", "--env", "SGCRod-v1", "--episodes", "1", "--no-plots",
            "--out", str(tmp_path)]  # fmt: skip
    assert main(argv) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("3/3 goals met, success 1.00, max error ") and last.endswith("rad")


def test_summary_line_reads_flattened_histories() -> None:
    line = summary_line({"goals_met": 0.0, "n_goals": 6.0, "success_rate": 0.0,
                         "position_error_max": 3.1, "orientation_error_max": float("nan"),
                         "terminated": 2.0})  # fmt: skip
    assert line == (
        "0/6 goals met, success 0.00, max error 3.1e+00 m, "
        "2 episode(s) failed (left the workspace or diverged)"
    )


@pytest.mark.parametrize(
    ("algo", "asked", "trained"),
    [("ppo", 5000, 6144), ("ppo", 2048, 2048), ("sac", 1001, 1001), ("ppo", 0, 0)],
)
def test_timesteps_round_up_to_whole_rollouts(algo, asked, trained) -> None:
    assert whole_rollouts(asked, algo, load_hyperparams(algo, "SGCPoint-v1")) == trained


def _help(command: str, capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit):
        build_parser().parse_args([command, "--help"])
    return capsys.readouterr().out


def test_help_shows_defaults(capsys) -> None:
    evaluate = _help("evaluate", capsys)
    assert "(default: 5)" in evaluate and "(default: 10000)" in evaluate
    assert "(default: None)" not in evaluate and "(default: False)" not in evaluate
    assert "(default: 0.02)" in evaluate
    train = _help("train", capsys)
    assert "training seed (default: 0)" in train and "(default: cpu)" in train


_DEMO_TABLE = """
import sys
from types import SimpleNamespace
from baselines.cli.console import demo_scorecard_table
from baselines.cli.console import make_console
rod = dict(rod="rod_gold", goals=25, goals_met=25, position_error_max_m=2.0e-15,
           orientation_error_max_rad=3.7e-15, closest_approach_offset_max_s=1.8e-15,
           sparc_track=-2.21, goal_speed_ratio_min=0.68, acceleration_kink=15.1,
           angular_acceleration_kink=29.2)
result = SimpleNamespace(label="expert", per_rod=[rod] * 3)
option = SimpleNamespace(policy="expert", end_rule="tangent")
make_console().print(demo_scorecard_table(option, result))
"""


def test_tables_in_a_log_keep_every_number_whole() -> None:
    """Piped to a file (a CI log), the demo's scorecard is not squeezed to 80 columns."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
    out = subprocess.run([sys.executable, "-c", _DEMO_TABLE], stdout=subprocess.PIPE,
                         text=True, check=True, env=env).stdout  # fmt: skip
    assert "…" not in out
    row = next(line for line in out.splitlines() if "rod_gold" in line)
    for cell in ("2.0e-15", "3.7e-15", "1.8e-15", "-2.21", "29.2"):
        assert cell in row, (cell, row)
    assert max(len(line) for line in out.splitlines()) > 80  # wider than the old pipe default
