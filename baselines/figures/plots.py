"""Figures for ``sgc evaluate`` and ``sgc rollout`` (matplotlib, object API, PNG files).

Figures are built on :class:`matplotlib.figure.Figure` directly, never through pyplot, so no
GUI backend or global state is involved and the functions are safe in tests and workers.
Inputs are plain arrays and dicts (rollout infos as in docs/design.md), not env objects.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from matplotlib.figure import Figure

__all__ = [
    "course_deviation",
    "plot_deviation_components",
    "plot_goal_errors",
    "plot_method_comparison",
    "plot_path_3d",
    "plot_speed_profile",
    "trajectory_arrays",
]

_COMPONENT_COLORS = ("tab:red", "tab:green", "tab:blue")


def trajectory_arrays(
    infos: Sequence[Mapping[str, Any]], initial_info: Mapping[str, Any] | None = None
) -> dict[str, np.ndarray]:
    """Stack rollout infos into arrays: ``time`` (n,), others (n, n_bodies, k).

    The reset info (if given) becomes sample 0 at time 0 with zero force and torque.
    """
    rows = list(infos)
    if initial_info is not None:
        first = dict(initial_info)
        first.setdefault("time", 0.0)
        rows.insert(0, first)
    keys = (
        "position_deviation", "orientation_deviation", "body_position", "body_orientation",
        "body_velocity", "body_angular_velocity", "point_position", "point_velocity",
    )  # fmt: skip
    out = {"time": np.array([float(r["time"]) for r in rows])}
    for key in keys:
        out[key] = np.stack([np.asarray(r[key], dtype=float) for r in rows])
    for key in ("force", "torque"):
        zero = np.zeros_like(np.asarray(rows[-1][key], dtype=float))
        out[key] = np.stack([np.asarray(r.get(key, zero), dtype=float) for r in rows])
    out["goal_index"] = np.stack([np.asarray(r["goal_index"]) for r in rows])
    return out


def course_deviation(
    traj: Mapping[str, np.ndarray], goals: Sequence[Sequence[Any]], body: int
) -> np.ndarray:
    """Tracked point minus the nail of the course each sample belongs to, (n, 3).

    A sample on a goal's tick belongs to the course that *ends* there, so an exact hit shows
    as zero; the env's own ``position_deviation`` already points at the next nail on that
    tick. Goals without a nail are skipped; after the last goal the last nail is kept.
    """
    nails = [g for g in goals[body] if g.nail is not None]
    points = traj["point_position"][:, body]
    if not nails:
        return np.zeros_like(points)
    times = np.array([g.time for g in nails])
    index = np.searchsorted(times, traj["time"] - 1e-9, side="left")
    targets = np.array([g.nail for g in nails], dtype=float)[np.minimum(index, len(nails) - 1)]
    return points - targets


def _goal_times(goals: Sequence[Sequence[Any]], body: int) -> list[float]:
    return [float(g.time) for g in goals[body]] if body < len(goals) else []


def _mark_goals(ax: Any, times: Sequence[float]) -> None:
    for t in times:
        ax.axvline(t, color="0.6", linestyle=":", linewidth=0.8)


def _save(fig: Figure, path: str | Path) -> Path:
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    return out


def plot_goal_errors(rows: Sequence[Mapping[str, Any]], path: str | Path, title: str = "") -> Path:
    """Per-goal position (and orientation) error, log scale: mean bar, min-max whiskers.

    Goals are labelled ``b<body>.g<goal>``; several episodes of a random env have different
    goals under one label, so the bars summarise the i-th goal of each body.
    """
    labels = sorted({(int(r["body"]), int(r["goal"])) for r in rows})
    fig = Figure(figsize=(max(5.0, 0.45 * len(labels) + 2.0), 3.6), layout="constrained")
    ax = fig.add_subplot()
    x = np.arange(len(labels))
    drawn = False
    for shift, key, color in (
        (-0.2, "position_error", "tab:blue"),
        (0.2, "orientation_error", "tab:orange"),
    ):
        stats = []
        for label in labels:
            vals = [r[key] for r in rows if (r["body"], r["goal"]) == label and r[key] is not None]
            vals = [v for v in vals if np.isfinite(v)]
            stats.append((np.mean(vals), np.min(vals), np.max(vals)) if vals else None)
        if not any(stats):
            continue
        xs = [xi + shift for xi, s in zip(x, stats, strict=True) if s]
        mean = np.array([max(s[0], 1e-17) for s in stats if s])
        lo = np.array([max(s[1], 1e-17) for s in stats if s])
        hi = np.array([max(s[2], 1e-17) for s in stats if s])
        unit = "m" if key == "position_error" else "rad"
        ax.bar(xs, mean, width=0.38, color=color, label=f"{key} ({unit})")
        yerr = [np.maximum(mean - lo, 0.0), np.maximum(hi - mean, 0.0)]
        ax.errorbar(xs, mean, yerr=yerr, fmt="none", ecolor="k", capsize=2)
        drawn = True
    ax.set_yscale("log")
    ax.set_xticks(x, [f"b{b}.g{g}" for b, g in labels], rotation=60, fontsize=7)
    ax.set_ylabel("error at goal time")
    ax.set_title(title or "error per goal")
    if drawn:
        ax.legend(fontsize=7)
    else:
        ax.text(0.5, 0.5, "no goal reached (episodes ended early)", ha="center",
                transform=ax.transAxes)  # fmt: skip
    return _save(fig, path)


Layout = Literal["constrained", "compressed", "tight"] | None
"""matplotlib's layout engines, or None for fixed margins."""


def _figure(size: tuple[float, float], layout: Layout) -> Figure:
    """A figure; ``layout=None`` uses fixed margins (matplotlib's layout engines cost about
    1.5 s of CPU per multi-row figure, a third of the demo's plotting)."""
    fig = Figure(figsize=size, layout=layout)
    if layout is None:
        fig.subplots_adjust(left=0.09, right=0.985, top=0.93, bottom=0.07, hspace=0.12,
                            wspace=0.2)  # fmt: skip
    return fig


def _body_names(n: int, names: Sequence[str] | None) -> list[str]:
    if names is None:
        return [f"body {b}" for b in range(n)]
    if len(names) != n:
        raise ValueError(f"names: expected {n} body names, got {len(names)}")
    return list(names)


def plot_speed_profile(
    traj: Mapping[str, np.ndarray],
    goals: Sequence[Sequence[Any]],
    path: str | Path,
    title: str = "",
    names: Sequence[str] | None = None,
    colors: Sequence[Any] | None = None,
    layout: Layout = "constrained",
) -> Path:
    """Tracked-point speed (and |omega|) against time, goal times dotted, per body.

    ``names``/``colors``: per body, so the figure matches a video (default ``body <i>``)."""
    n_bodies = traj["point_velocity"].shape[1]
    labels = _body_names(n_bodies, names)
    fig = _figure((7.0, 1.8 + 1.6 * n_bodies), layout)
    axes = fig.subplots(n_bodies, 1, sharex=True, squeeze=False)[:, 0]
    t = traj["time"]
    for b, ax in enumerate(axes):
        color = None if colors is None else colors[b]
        ax.plot(t, np.linalg.norm(traj["point_velocity"][:, b], axis=1), label="|v| point (m/s)",
                color=color)  # fmt: skip
        omega = np.linalg.norm(traj["body_angular_velocity"][:, b], axis=1)
        if np.max(omega, initial=0.0) > 1e-9:
            ax.plot(t, omega, label="|omega| (rad/s)", alpha=0.6, color="0.45", linewidth=0.9)
        _mark_goals(ax, _goal_times(goals, b))
        ax.set_ylabel(labels[b], **({} if color is None else {"color": color}))
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title(title or "speed profile (goal times dotted)")
    return _save(fig, path)


def plot_deviation_components(
    traj: Mapping[str, np.ndarray],
    goals: Sequence[Sequence[Any]],
    path: str | Path,
    title: str = "",
    names: Sequence[str] | None = None,
    colors: Sequence[Any] | None = None,
    layout: Layout = "constrained",
) -> Path:
    """Each component of D (and phi where present) against time, goal times dotted.

    ``names``/``colors`` label each body's row (default ``body <i>``, black).

    D is :func:`course_deviation` (zero at an exact hit); phi is the env's, which on a goal's
    tick already refers to the next orientation goal.
    """
    n_bodies = traj["position_deviation"].shape[1]
    labels = _body_names(n_bodies, names)
    has_phi = [bool(np.any(traj["orientation_deviation"][:, b] != 0.0)) for b in range(n_bodies)]
    cols = 2 if any(has_phi) else 1
    fig = _figure((5.0 * cols, 1.8 + 1.8 * n_bodies), layout)
    axes = fig.subplots(n_bodies, cols, sharex=True, squeeze=False)
    t = traj["time"]
    for b in range(n_bodies):
        for c, (key, name) in enumerate(
            (("position_deviation", "D (m)"), ("orientation_deviation", "phi (rad)"))[:cols]
        ):
            ax = axes[b, c]
            if c == 1 and not has_phi[b]:
                ax.set_visible(False)
                continue
            values = course_deviation(traj, goals, b) if c == 0 else traj[key][:, b]
            for j, color in enumerate(_COMPONENT_COLORS):
                ax.plot(t, values[:, j], color=color, label="xyz"[j], linewidth=1.0)
            _mark_goals(ax, _goal_times(goals, b))
            ax.axhline(0.0, color="k", linewidth=0.5)
            ax.set_ylabel(f"{labels[b]} {name}", **({} if colors is None else {"color": colors[b]}))
            ax.legend(fontsize=7, loc="upper right")
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    fig.suptitle(title or "deviation components (goal times dotted)")
    return _save(fig, path)


def plot_path_3d(
    traj: Mapping[str, np.ndarray],
    goals: Sequence[Sequence[Any]],
    path: str | Path,
    title: str = "",
) -> Path:
    """3-D path of each body's tracked point with its nails (crosses)."""
    fig = Figure(figsize=(5.5, 5.0), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    pts = traj["point_position"]
    for b in range(pts.shape[1]):
        line = ax.plot(pts[:, b, 0], pts[:, b, 1], pts[:, b, 2], label=f"body {b}")[0]
        nails = np.array([g.nail for g in goals[b] if g.nail is not None] if b < len(goals) else [])
        if len(nails):
            ax.scatter(
                nails[:, 0], nails[:, 1], nails[:, 2], marker="x", s=40, color=line.get_color()
            )
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title or "tracked point path and nails")
    ax.legend(fontsize=7)
    return _save(fig, path)


def plot_method_comparison(
    runs: Mapping[str, Mapping[str, np.ndarray]],
    goals: Sequence[Sequence[Any]],
    path: str | Path,
    body: int = 0,
    title: str = "",
) -> Path:
    """The paper's Figures 1 and 2 side by side: |D| and speed against time per method.

    ``runs`` maps a method name (e.g. "dynamic constraints", "sequential-goal constraints")
    to its trajectory arrays on the *same* scenario. Top row: distance of the tracked point to
    the nail of the current course (:func:`course_deviation`, log scale); bottom row: its
    speed. Dynamic constraints dip where *they* decide a goal is met, SGC at the goal times.
    """
    names = list(runs)
    fig = Figure(figsize=(4.6 * len(names), 5.2), layout="constrained")
    axes = fig.subplots(2, len(names), sharex=True, squeeze=False)
    times = _goal_times(goals, body)
    for c, name in enumerate(names):
        traj = runs[name]
        t = traj["time"]
        dist = np.linalg.norm(course_deviation(traj, goals, body), axis=1)
        speed = np.linalg.norm(traj["point_velocity"][:, body], axis=1)
        axes[0, c].semilogy(t, np.maximum(dist, 1e-16))
        axes[0, c].set_title(name)
        axes[0, c].set_ylabel("|D| to the course's nail (m)")
        axes[1, c].plot(t, speed)
        axes[1, c].set_ylabel("speed (m/s)")
        axes[1, c].set_xlabel("time (s)")
        for ax in axes[:, c]:
            _mark_goals(ax, times)
    fig.suptitle(title or f"body {body}: dynamic constraints vs sequential-goal constraints")
    return _save(fig, path)


def plot_evaluation(result: Any, folder: Path) -> None:
    """``goal_errors.png`` and (from episode 0's infos) ``speed_profile.png`` of one
    harness result (:class:`~baselines.evaluation.harness.EvaluationResult`)."""
    title = f"{result.policy} on {result.env_id}"
    plot_goal_errors(result.rows, folder / "goal_errors.png", title=title)
    first = result.episodes[0]
    if first.infos:
        traj = trajectory_arrays(first.infos, first.initial_info)
        plot_speed_profile(traj, first.goals, folder / "speed_profile.png", title=f"{title}, ep 0")
