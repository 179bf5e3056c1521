"""Which ``sgc benchmark`` process runs which run: one exclusive lock per run folder.

Two benchmarks on one ``--out`` (a second terminal, a resumed command while the first still
runs) must not train the same run twice or write one run's files at the same time. Before a
run starts, its driver takes a non-blocking ``flock`` on ``<run folder>/.claim`` and holds it
until the run's outcome is written; a run another process holds is left to that process. The
kernel drops the lock when its process ends, however it ends (SIGKILL included), so a killed
benchmark never leaves a run locked. Where ``fcntl`` does not exist (Windows) every claim
succeeds, as before.

The leaderboard is one file for the whole ``--out``: each benchmark rewrites it when it ends,
from the records it reads then. :func:`report_lock` makes that read and write one step
(a blocking ``flock`` on ``<out>/.report-claim``), so the benchmark that reports last has
read every record written before it, and a stale reader never overwrites a fuller board.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None  # type: ignore[assignment]

__all__ = ["CLAIM_FILE", "REPORT_CLAIM_FILE", "RunClaims", "report_lock"]

CLAIM_FILE = ".claim"
REPORT_CLAIM_FILE = ".report-claim"


class RunClaims:
    """The run folders this process holds (see the module docstring)."""

    def __init__(self) -> None:
        self._held: dict[Path, int] = {}

    def claim(self, folder: str | Path) -> bool:
        """Take ``folder``'s lock if no other process holds it; False when one does."""
        path = Path(folder)
        if path in self._held:
            return True
        path.mkdir(parents=True, exist_ok=True)
        fd = os.open(path / CLAIM_FILE, os.O_RDWR | os.O_CREAT, 0o644)
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                return False
        self._held[path] = fd
        return True

    def release(self, folder: str | Path) -> None:
        fd = self._held.pop(Path(folder), None)
        if fd is not None:
            os.close(fd)  # closing the descriptor drops its lock

    def release_all(self) -> None:
        for folder in list(self._held):
            self.release(folder)


@contextmanager
def report_lock(root: str | Path) -> Iterator[None]:
    """Hold ``root``'s report lock (waiting for another benchmark's report to finish)."""
    path = Path(root)
    path.mkdir(parents=True, exist_ok=True)
    fd = os.open(path / REPORT_CLAIM_FILE, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing the descriptor drops its lock
