"""scripts/zoo_seed_table.py: training seconds from rl-zoo3's Monitor files, read bounded."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.script_module import load_script


def _script():
    return load_script("zoo_seed_table")


def test_training_seconds_span_every_monitor_file(tmp_path: Path) -> None:
    (tmp_path / "0.monitor.csv").write_text('#{"t_start": 100.0}\nr,l,t\n1,5,2.5\n1,5,7.0\n')
    (tmp_path / "1.monitor.csv").write_text('#{"t_start": 101.0}\nr,l,t\n1,5,8.5\n')
    assert _script().training_seconds(tmp_path) == pytest.approx(9.5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("r,l,t\n1,5,2.5\n", "no '#{...}' header line"),
        ('#{"x": 1}\nr,l,t\n1,5,2.5\n', "no t_start in the header"),
        ('#{"t_start": 1e400}\nr,l,t\n1,5,2.5\n', "must be finite"),
        ('#{"t_start": 1.0\nr,l,t\n', "not valid JSON"),
    ],
)
def test_a_bad_monitor_file_is_one_line_naming_it(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "0.monitor.csv").write_text(text)
    with pytest.raises(ValueError, match="0.monitor.csv") as caught:
        _script().training_seconds(tmp_path)
    assert message in str(caught.value) and "\n" not in str(caught.value)
