"""scripts/zoo_study_table.py: one row per family from rl-zoo3's Optuna reports, read bounded."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.script_module import load_script

HEADER = (",number,value,datetime_start,datetime_complete,duration,params_learning_rate,"
          "user_attrs_gamma,user_attrs_batch_size,state\n")  # fmt: skip


def _script():
    return load_script("zoo_study_table")


def _report(folder: Path, rows: str, stamp: int = 1700000000) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    name = f"report_SGCPoint-v1_3-trials-50000-tpe-median_{stamp}.csv"
    (folder / name).write_text(HEADER + rows)


def test_a_row_counts_trials_and_reads_the_best_settings(tmp_path: Path) -> None:
    _report(tmp_path / "sac", (
        "0,0,10.5,a,b,0 days 00:01:00.5,0.001,0.98,256,COMPLETE\n"
        "1,1,30.25,a,b,0 days 00:02:00,0.0003,0.95,64,COMPLETE\n"
        "2,2,,a,b,0 days 00:00:30,0.01,0.9,32,PRUNED\n"
    ))  # fmt: skip
    _report(tmp_path / "sac", "0,0,99,a,b,0 days 00:00:01,0.1,0.5,8,COMPLETE\n", 1600000000)
    row = _script().study_row(tmp_path / "sac")  # the newest report, not the older one
    assert (row["trials"], row["complete"], row["pruned"], row["failed"]) == (3, 2, 1, 0)
    assert row["best"] == 30.25 and row["median"] == pytest.approx(20.375)
    assert row["settings"] == {"gamma": "0.95", "learning_rate": "0.0003", "batch_size": "64"}
    assert row["steps_per_trial"] == 50000 and row["seconds"] == 210
    assert "| SAC | SGCPoint-v1 | 3 (2 / 1 / 0) | 50,000 | 30.2 |" in _script().markdown([row])


@pytest.mark.parametrize(
    ("rows", "message"),
    [("0,0,inf,a,b,0 days 00:00:01,0.1,0.5,8,COMPLETE\n", "trial 0: inf is not finite"),
     ("0,0,x,a,b,0 days 00:00:01,0.1,0.5,8,COMPLETE\n", "trial 0: 'x' is not a number"),
     ("0,0,,a,b,0 days 00:00:01,0.1,0.5,8,FAIL\n", "no completed trial"),
     ("0,../x,5,a,b,0 days 00:00:01,0.1,0.5,8,COMPLETE\n", "trial number '../x' is not a count")],
)  # fmt: skip
def test_a_bad_report_names_the_file_and_the_trial(tmp_path: Path, rows: str, message: str) -> None:
    _report(tmp_path / "td3", rows)
    with pytest.raises(ValueError, match=f"study report .*report_SGCPoint-v1.*{message}"):
        _script().study_row(tmp_path / "td3")


def test_a_folder_without_reports_says_how_to_make_them(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no rl-zoo3 report_.*scripts/zoo_study.sh"):
        _script().study_row(tmp_path)


def test_scoring_needs_the_best_trials_model(tmp_path: Path) -> None:
    _report(tmp_path / "ppo", "0,0,5,a,b,0 days 00:00:01,0.1,0.5,8,COMPLETE\n")
    script = _script()
    row = script.study_row(tmp_path / "ppo")
    with pytest.raises(ValueError, match=r"trial_0/best_model.zip: no model of the best trial"):
        script.score_best(row, tmp_path / "ppo", 1, 20000)
