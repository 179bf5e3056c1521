"""``sgc bench``: both benchmarks run from the command and print their ratios; a bad
reference or pair is one clean line before any timing. ``compare`` swaps ``sgc_env`` modules
in its process, so it runs in a child process here."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from baselines.cli.main import main

ROOT = Path(__file__).resolve().parents[3]


def _sgc(*words: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "baselines.cli.main", *words], capture_output=True, text=True,
        cwd=ROOT, timeout=300,
    )  # fmt: skip


def test_env_prints_a_ratio_per_id(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["bench", "env", "--steps", "20", "--resets", "2", "--rounds", "2", "--draws", "1"]
    assert main([*argv, "--ids", "SGCRod-v1"]) == 0
    row = capsys.readouterr().out.strip().splitlines()[-1].split()
    assert row[0] == "SGCRod-v1" and float(row[3]) > 1.0  # the env costs more than its physics


def test_compare_against_a_checkout_with_the_bare_loop() -> None:
    done = _sgc("bench", "compare", "--reference", str(ROOT), "--pair", "SGCPoint-v1=SGCPoint-v1",
                "--rounds", "2", "--chunk", "20")  # fmt: skip
    assert done.returncode == 0, done.stderr
    header, row = done.stdout.strip().splitlines()
    assert header.split()[-2:] == ["us", "new/bare"]
    name, *figures = row.split()
    assert name == "SGCPoint-v1" and all(float(x) > 0.0 for x in figures)


def test_compare_runs_every_pair_asked_for() -> None:
    """An id in --ids and again in --pair, or twice in --pair, is timed each time it is named."""
    done = _sgc("bench", "compare", "--reference", str(ROOT), "--ids", "SGCPoint-v1",
                "--pair", "SGCPoint-v1=SGCPoint-v1", "--pair", "SGCPoint-v1=SGCPoint-v1",
                "--rounds", "1", "--chunk", "5")  # fmt: skip
    assert done.returncode == 0, done.stderr
    rows = done.stdout.strip().splitlines()[1:]
    assert [row.split()[0] for row in rows] == ["SGCPoint-v1"] * 3


def test_a_bad_reference_or_pair_is_one_line(tmp_path: Path) -> None:
    done = _sgc("bench", "compare", "--reference", str(tmp_path), "--rounds", "1")
    assert done.returncode == 2 and done.stdout == ""
    assert (
        done.stderr.strip()
        == f"sgc bench: error: --reference {tmp_path}: holds no sgc_env/ package"
    )
    done = _sgc("bench", "compare", "--reference", str(ROOT), "--pair", "SGCPoint-v1=Nope-v0")
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.strip().splitlines() == [
        f"sgc bench: error: SGCPoint-v1=Nope-v0: NEW must be registered here and OLD at {ROOT}"
    ]
