"""baselines/benchmark/claims.py: one run per process, one leaderboard writer at a time."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from baselines.benchmark.claims import RunClaims, report_lock

pytest.importorskip("fcntl", reason="the locks are POSIX flocks")


def test_a_run_held_by_one_claimant_is_refused_to_another(tmp_path: Path) -> None:
    first, second = RunClaims(), RunClaims()
    assert first.claim(tmp_path / "run") and not second.claim(tmp_path / "run")
    first.release_all()
    assert second.claim(tmp_path / "run")
    second.release_all()


def test_a_report_waits_for_the_report_under_way(tmp_path: Path) -> None:
    entered = threading.Event()

    def second_report() -> None:
        with report_lock(tmp_path):
            entered.set()

    with report_lock(tmp_path):
        waiter = threading.Thread(target=second_report)
        waiter.start()
        assert not entered.wait(0.3), "a second report ran while the first held the lock"
    waiter.join(timeout=10)
    assert entered.is_set()
