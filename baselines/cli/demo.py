"""The paper's three-rod demo, run by the expert and written out as a viewer would want it.

One episode of ``SGCThreeRods-v0`` driven by :class:`baselines.SGCExpert`, scored by the shared
harness, and rendered headless (TinyRenderer) with a ground, a target board with a bullseye,
and fading trails behind each rod's tip. Outputs: an MP4 and a GIF, an 8-frame plate sheet in
the spirit of the paper's Plates 1-8, deviation plots per rod, ``goals.csv`` and
``summary.json``.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sgc_env.rendering import CameraConfig
from sgc_env.simulator import Simulator, pybullet

__all__ = ["DEMO_CAMERA", "DemoOptions", "DemoResult", "TipTrails", "run_demo"]

ENV_ID = "SGCThreeRods-v0"
DEMO_CAMERA = CameraConfig(
    distance=12.5, yaw=0.0, pitch=-11.0, target=(-0.4, 0.0, 3.4), width=960, height=540, fov=52.0
)
GROUND_COLOR = (0.62, 0.68, 0.62, 1.0)
PLATES = 8


@dataclass(frozen=True)
class DemoOptions:
    """What to render: ``frame_every`` control ticks per video frame (60 Hz / 2 = 30 fps)."""

    out: Path
    width: int = DEMO_CAMERA.width
    height: int = DEMO_CAMERA.height
    frame_every: int = 2
    gif_scale: int = 2
    trail_length: int = 90
    video: bool = True

    def __post_init__(self) -> None:
        for name in ("width", "height", "frame_every", "gif_scale", "trail_length"):
            value = getattr(self, name)
            if not isinstance(value, int) or value < 1:
                raise ValueError(f"{name}: expected a positive integer, got {value!r}")


@dataclass
class DemoResult:
    """Where everything went, and the scorecard."""

    files: dict[str, Path] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    per_rod: list[dict[str, Any]] = field(default_factory=list)


class TipTrails:
    """Visual-only spheres left behind each tip: a ring buffer per rod (physics untouched)."""

    def __init__(self, sim: Simulator, colors: Sequence[Sequence[float]], length: int) -> None:
        self.sim = sim
        self.length = length
        self.markers = [
            [sim.add_marker(0.05 * (0.3 + 0.7 * k / length), _faded(c, k / length))
             for k in range(length)]
            for c in colors
        ]  # fmt: skip
        self.history: list[list[tuple[float, float, float]]] = [[] for _ in colors]

    def update(self, tips: np.ndarray) -> None:
        for rod, tip in enumerate(np.asarray(tips, dtype=float)):
            trail = self.history[rod]
            trail.append(tuple(tip))
            del trail[: -self.length]
            for marker, position in zip(self.markers[rod][-len(trail):], trail, strict=True):
                self.sim.move(marker, position)


def _faded(color: Sequence[float], age: float) -> tuple[float, float, float, float]:
    """Blend towards white for older trail points."""
    r, g, b = (float(c) for c in color[:3])
    mix = 0.25 + 0.75 * age
    return (1 - mix + mix * r, 1 - mix + mix * g, 1 - mix + mix * b, 1.0)


def dress_scene(sim: Simulator, target_center: Sequence[float], board_half: Sequence[float]):
    """A ground and a bullseye on the target board (visual only)."""
    client = sim.client
    ground = pybullet.createVisualShape(
        pybullet.GEOM_BOX, halfExtents=[30.0, 30.0, 0.02], rgbaColor=list(GROUND_COLOR),
        physicsClientId=client,
    )  # fmt: skip
    pybullet.createMultiBody(0.0, -1, ground, [0.0, 0.0, -0.02], physicsClientId=client)
    face_x = target_center[0] - board_half[0] - 0.005
    rings = ((1.6, (0.85, 0.1, 0.1, 1.0)), (1.1, (0.95, 0.95, 0.95, 1.0)),
             (0.6, (0.85, 0.1, 0.1, 1.0)), (0.2, (0.95, 0.85, 0.2, 1.0)))  # fmt: skip
    turn = pybullet.getQuaternionFromEuler([0.0, np.pi / 2, 0.0])
    for k, (radius, color) in enumerate(rings):
        disc = pybullet.createVisualShape(
            pybullet.GEOM_CYLINDER, radius=radius, length=0.01, rgbaColor=list(color),
            physicsClientId=client,
        )  # fmt: skip
        position = [face_x - 0.006 * k, target_center[1], target_center[2]]
        pybullet.createMultiBody(0.0, -1, disc, position, turn, physicsClientId=client)


def run_demo(
    options: DemoOptions, progress: Callable[[int, int], None] | None = None
) -> DemoResult:
    """Run, score and render the demo; ``progress(done, total)`` is called every tick."""
    import gymnasium as gym

    from baselines.evaluation import (
        goal_rows,
        run_episode,
        summarize,
        write_goals_csv,
        write_summary_json,
    )
    from baselines.expert import SGCExpert

    options.out.mkdir(parents=True, exist_ok=True)
    camera = {**asdict(DEMO_CAMERA), "width": options.width, "height": options.height}
    env = gym.make(ENV_ID, render_mode="rgb_array", camera=camera)
    base: Any = env.unwrapped
    target = next(p for p in base.scenario.props if p.name == "target")
    dress_scene(base.sim, target.position, target.size)
    trails = TipTrails(base.sim, [b.color for b in base.scenario.bodies], options.trail_length)
    total = base.max_steps
    frames: list[Any] = []
    frame_times: list[float] = []

    def on_step(env_: Any, step: int, info: Mapping[str, Any]) -> None:
        trails.update(info["point_position"])
        if options.video and step % options.frame_every == 0:
            frames.append(env_.render())
            frame_times.append(float(info.get("time", 0.0)))
        if progress is not None:
            progress(step, total)

    expert = SGCExpert(env)
    record = run_episode(expert, env, seed=0, keep_infos=True, on_step=on_step)
    env.close()

    result = DemoResult()
    rows = goal_rows(record, ENV_ID, "expert")
    result.summary = summarize([record], rows)
    result.files["goals.csv"] = write_goals_csv(rows, options.out / "goals.csv")
    result.files["summary.json"] = write_summary_json(result.summary, options.out / "summary.json")
    result.per_rod = _per_rod(record, rows, base.scenario)
    per_rod_path = options.out / "rods.json"
    per_rod_path.write_text(json.dumps(result.per_rod, indent=2))
    result.files["rods.json"] = per_rod_path
    result.files.update(_plots(record, options.out))
    if options.video and frames:
        result.files.update(_videos(frames, frame_times, options))
    return result


def _per_rod(record: Any, rows: Sequence[Mapping[str, Any]], scenario: Any) -> list[dict[str, Any]]:
    """Exactness, punctuality and smoothness for each rod, from the harness's rows and card."""
    out = []
    for b, body in enumerate(scenario.bodies):
        mine = [r for r in rows if r["body"] == b]
        card = record.card["bodies"][b]
        position = [r["position_error"] for r in mine if r["position_error"] is not None]
        orientation = [r["orientation_error"] for r in mine if r["orientation_error"] is not None]
        offsets = [abs(r["position_closest_offset"]) for r in mine
                   if r["position_closest_offset"] is not None]  # fmt: skip
        out.append(
            {
                "rod": body.name,
                "goals": len(body.goals),
                "position_error_max_m": max(position),
                "orientation_error_max_rad": max(orientation) if orientation else None,
                "closest_approach_offset_max_s": max(offsets) if offsets else None,
                "sparc_track": card.get("sparc_track"),
                "goal_speed_ratio_min": card.get("goal_speed_ratio_min"),
                "speed_minima": card.get("speed_minima_total"),
                "goals_met": card.get("goals_met"),
            }
        )
    return out


def _plots(record: Any, out: Path) -> dict[str, Path]:
    from baselines.cli.plots import plot_deviation_components, plot_speed_profile, trajectory_arrays

    traj = trajectory_arrays(record.infos, record.initial_info)
    return {
        "deviation.png": plot_deviation_components(
            traj, record.goals, out / "deviation.png",
            title="three rods: deviation of each tip (D) and orientation (phi), goal times dotted",
        ),
        "speed.png": plot_speed_profile(traj, record.goals, out / "speed.png"),
    }  # fmt: skip


def _videos(frames: list[Any], times: list[float], options: DemoOptions) -> dict[str, Path]:
    import imageio.v2 as imageio
    from matplotlib.figure import Figure

    fps = 60 / options.frame_every
    mp4 = options.out / "three_rods.mp4"
    imageio.mimwrite(mp4, frames, fps=fps, codec="libx264", quality=7, macro_block_size=4)
    gif = options.out / "three_rods.gif"
    small = [f[:: options.gif_scale, :: options.gif_scale] for f in frames[::2]]
    imageio.mimwrite(gif, small, duration=1000 * 2 / fps, loop=0)
    picks = np.linspace(0, len(frames) - 1, PLATES).round().astype(int)
    fig = Figure(figsize=(16, 5.2), layout="constrained")
    axes = fig.subplots(2, PLATES // 2)
    for k, (ax, i) in enumerate(zip(axes.ravel(), picks, strict=True)):
        ax.imshow(frames[i])
        ax.set_title(f"Plate {k + 1}  (t = {times[i]:.2f} s)", fontsize=10)
        ax.axis("off")
    plates = options.out / "plates.png"
    fig.savefig(plates, dpi=100)
    return {"three_rods.mp4": mp4, "three_rods.gif": gif, "plates.png": plates}
