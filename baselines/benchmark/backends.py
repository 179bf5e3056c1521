"""Where benchmark runs execute: a local process pool (default) or Ray tasks.

Both take run specs as dicts, call :func:`~baselines.benchmark.execute.execute_run` and
yield each outcome to the driver as it finishes; the driver writes it. A run trains with one
torch thread and seeded envs, so the same spec gives the same numbers on either backend.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Any

from baselines.benchmark.execute import execute_run

__all__ = ["BACKENDS", "LocalBackend", "RayBackend", "make_backend"]

BACKENDS: tuple[str, ...] = ("local", "ray")

Started = Callable[[str], None]
Claim = Callable[[dict[str, Any]], bool]


def _throttled(
    specs: Sequence[dict[str, Any]],
    capacity: int,
    submit: Callable[[dict[str, Any]], Any],
    wait_some: Callable[[list[Any]], tuple[list[Any], list[Any]]],
    collect: Callable[[Any], dict[str, Any]],
    on_start: Started | None,
    claim: Claim | None = None,
) -> Iterator[dict[str, Any]]:
    """Keep at most ``capacity`` runs in flight (so "running" means running), yield outcomes.

    A run whose worker dies (killed, out of memory) comes back as a failed outcome, like a
    run that raised, so that the grid goes on and records it. ``claim(spec)`` is asked just
    before a run starts; a run it refuses (another process has it) is skipped.
    """
    queue = list(specs)
    owners: dict[int, dict[str, Any]] = {}
    pending: list[Any] = []
    while queue or pending:
        while queue and len(pending) < capacity:
            spec = queue.pop(0)
            if claim is not None and not claim(spec):
                continue
            if on_start is not None:
                on_start(spec["run_id"])
            handle = submit(spec)
            owners[id(handle)] = spec
            pending.append(handle)
        if not pending:
            break
        done, pending = wait_some(pending)
        for handle in done:
            spec = owners.pop(id(handle))
            try:
                yield collect(handle)
            except Exception as exc:  # noqa: BLE001 - the worker itself was lost
                yield {"run_id": spec["run_id"], "spec": spec, "status": "failed",
                       "error": f"worker lost: {type(exc).__name__}: {exc}",
                       "traceback": "", "wall_time_s": 0.0}  # fmt: skip


class LocalBackend:
    """A spawn-context pool of ``workers`` processes (default: the machine's cores).

    With one worker the runs execute in this process, one after another.
    """

    def __init__(self, workers: int | None = None) -> None:
        workers = (os.cpu_count() or 1) if workers is None else workers
        if workers < 1:
            raise ValueError(f"--workers must be >= 1, got {workers}")
        self.workers = workers
        self.description = f"local process pool, {workers} worker(s)"

    def run(
        self, specs: Sequence[dict[str, Any]], on_start: Started | None = None,
        claim: Claim | None = None,
    ) -> Iterator[dict[str, Any]]:
        """Yield each run's outcome as it finishes (``on_start(run_id)`` when one begins,
        ``claim(spec)`` just before: see :func:`_throttled`)."""
        if not specs:
            return
        if self.workers == 1:  # one at a time: in this process, no start-up cost
            yield from _throttled(specs, 1, execute_run, lambda pending: (pending, []),
                                  lambda out: out, on_start, claim)  # fmt: skip
            return
        context = multiprocessing.get_context("spawn")  # no forked torch/PyBullet state
        with ProcessPoolExecutor(min(self.workers, len(specs)), mp_context=context) as pool:

            def wait_some(pending: list[Any]) -> tuple[list[Any], list[Any]]:
                done, rest = wait(pending, return_when=FIRST_COMPLETED)
                return list(done), list(rest)

            yield from _throttled(
                specs, self.workers, lambda spec: pool.submit(execute_run, spec), wait_some,
                lambda future: future.result(), on_start, claim,
            )  # fmt: skip


class RayBackend:
    """Each run a Ray task with ``cpus_per_run`` CPUs; outcomes return to the driver.

    ``address``: an existing cluster (``ray start --head`` prints it, or ``auto``); without
    one a local instance is started with ``num_cpus`` (default: the machine's cores). The
    nodes need this package installed (``pip install sgc[rl,ray]``).
    """

    def __init__(
        self, address: str | None = None, cpus_per_run: float = 1.0, num_cpus: int | None = None
    ) -> None:
        try:
            import ray
        except ImportError as exc:
            raise ValueError(
                "--backend ray needs Ray: pip install 'sgc[ray]' (ray[default])"
            ) from exc
        if cpus_per_run <= 0:
            raise ValueError(f"--cpus-per-run must be > 0, got {cpus_per_run}")
        self.ray = ray
        self.address = address
        self.cpus_per_run = cpus_per_run
        self.num_cpus = num_cpus
        where = address or "a local instance"
        self.description = f"Ray at {where}, {cpus_per_run} CPU per run"

    def _init(self) -> bool:
        """Connect or start Ray; True when this backend started it (and so shuts it down)."""
        if self.ray.is_initialized():
            return False
        kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
        if self.address:
            kwargs["address"] = self.address
        else:
            kwargs["num_cpus"] = self.num_cpus or os.cpu_count() or 1
        self.ray.init(**kwargs)
        return True

    def run(
        self, specs: Sequence[dict[str, Any]], on_start: Started | None = None,
        claim: Claim | None = None,
    ) -> Iterator[dict[str, Any]]:
        """Submit every run as a task and yield outcomes in the order they finish."""
        if not specs:
            return
        started_here = self._init()
        try:
            task = self.ray.remote(num_cpus=self.cpus_per_run, max_retries=0)(execute_run)
            cpus = float(self.ray.cluster_resources().get("CPU", 1.0))
            capacity = max(int(cpus // self.cpus_per_run), 1)

            def wait_some(pending: list[Any]) -> tuple[list[Any], list[Any]]:
                return self.ray.wait(pending, num_returns=1)

            yield from _throttled(specs, capacity, task.remote, wait_some, self.ray.get, on_start,
                                  claim)  # fmt: skip
        finally:
            if started_here:
                self.ray.shutdown()


def make_backend(
    name: str,
    workers: int | None = None,
    address: str | None = None,
    cpus_per_run: float = 1.0,
) -> LocalBackend | RayBackend:
    """The backend called ``name`` (``ValueError`` naming the choices otherwise)."""
    if name == "local":
        if address:
            raise ValueError("--address is for --backend ray")
        return LocalBackend(workers)
    if name == "ray":
        return RayBackend(address, cpus_per_run, num_cpus=workers)
    raise ValueError(f"--backend: expected one of {BACKENDS}, got {name!r}")
