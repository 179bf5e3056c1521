"""The paper's three-rod demo, flown by a policy and written out as a viewer would want it.

One episode of ``SGCThreeRods-v2`` driven by :class:`baselines.SGCExpert` (the tangent
end-velocity rule by default, the paper's eqs. 12-14 with ``end_rule="paper"``) or by any
policy spec :func:`baselines.policies.make_policy` accepts (``DemoOptions.policy``), scored by
the shared harness, and rendered headless through the renderer of ``env.render()``
(:mod:`sgc_env.render`: TinyRenderer for the bodies, then sky, checkered floor, shadows,
fading trails, nails) from the cameras of :mod:`baselines.figures.demo_camera`. Rods are drawn
thicker than their physical radius, and each red ball that its rod's tip really met (came
within the ball's radius of its centre, :func:`pierce_times`) rides on that rod from the tick
of closest approach on; a ball never met flies on along its own path (visual only: the render
world is a client of its own, physics is untouched). The episode runs first and is drawn
afterwards, so that the pierce is known when the frames are drawn.
Outputs: an MP4 and a GIF at real time, an
8-frame plate sheet in the spirit of the paper's Plates 1-8, deviation and speed plots per rod
(named and coloured as in the video), ``goals.csv``, ``summary.json``, ``rods.json`` and the
flight as a keyframed glTF scene, ``three_rods.glb`` (rods drawn as thick as in the video),
with ``viewer.html`` to show it in a browser.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from baselines.figures.demo_camera import camera_at
from baselines.figures.episode_gif import gif_durations, write_gif
from sgc_env.export.gltf import VIEWER_PAGE, Motion, motion_of, write_glb, write_viewer
from sgc_env.paper.end_rules import END_RULES
from sgc_env.render import TRAIL_SECONDS, Caster, Painter, RenderWorld, Trail
from sgc_env.simulator import pybullet

__all__ = [
    "GLTF_FILE", "BallCarry", "DemoOptions", "DemoResult", "DemoScene", "check_policy",
    "cpu_seconds", "demo_env_id", "demo_motion", "demo_policy", "gif_durations", "open_demo",
    "pierce_times", "run_demo",
]  # fmt: skip

ENV_ID = "SGCThreeRods-v2"
"""The paper's scene: the expert, the hand-written controllers and learned models fly it."""
PLATE_TIMES = (0.5, 1.25, 2.4, 3.6, 4.6, 5.8, 7.05, 8.3)
"""Moments the plates show: launch, piercing, flight, somersault, the hits, all three in."""
ROD_DRAW_RADIUS = 0.075
"""Drawn rod radius (m): the physical 0.04 m reads as a hair at video size."""
BALL_SLIDE = 0.3
"""Seconds a pierced ball takes to slide from the tip to the middle of its rod."""
VIDEO_FPS = 30
GLTF_FILE = "three_rods.glb"
"""The flight as glTF 2.0 binary (:mod:`sgc_env.export.gltf`), for Blender and the web."""


@dataclass(frozen=True)
class DemoOptions:
    """What to run and render. ``policy``: a spec of :func:`baselines.policies.make_policy`;
    ``end_rule``: the expert's end-velocity rule (for ``policy="expert"`` only);
    ``trust_model``: unpickle model files (``--trust-model``); ``gltf``: write the flight as
    :data:`GLTF_FILE`."""

    out: Path
    width: int = 960
    height: int = 540
    gif_scale: int = 2
    video: bool = True
    gltf: bool = True
    end_rule: str = "tangent"
    policy: str = "expert"
    trust_model: bool = False

    def __post_init__(self) -> None:
        for name in ("width", "height", "gif_scale"):
            value = getattr(self, name)
            if not isinstance(value, int) or value < 1:
                raise ValueError(f"{name}: expected a positive integer, got {value!r}")
        if self.end_rule not in END_RULES:
            raise ValueError(f"end_rule: expected one of {END_RULES}, got {self.end_rule!r}")
        if not isinstance(self.policy, str) or not self.policy:
            raise ValueError(f"policy: expected a non-empty spec, got {self.policy!r}")
        if self.end_rule != "tangent" and self.policy != "expert":
            raise ValueError(
                f"end_rule: applies to the expert only, not to policy {self.policy!r} "
                "(for the paper's rule use policy 'expert-paper')"
            )

    @property
    def label(self) -> str:
        """The policy's name in tables, panels and ``goals.csv``."""
        if self.policy == "expert":
            return "expert" if self.end_rule == "tangent" else "expert-paper"
        from baselines.policies import policy_label

        return policy_label(self.policy)


@dataclass
class DemoResult:
    """Where everything went, the scorecard, the CPU seconds the run took, and the video's
    frames with their times and the flight's motion (for ``sgc demo --compare``)."""

    files: dict[str, Path] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    per_rod: list[dict[str, Any]] = field(default_factory=list)
    cpu_s: float = 0.0
    label: str = "expert"
    frames: list[np.ndarray] = field(default_factory=list)
    frame_times: list[float] = field(default_factory=list)
    motion: Motion | None = None
    scenario: Any = None


_AT_IMPORT = os.times()
_EARLIER_CHILDREN = _AT_IMPORT.children_user + _AT_IMPORT.children_system
"""Children's CPU already counted when this module loads: a shell that runs ``setup.sh && sgc
demo`` as ``bash -c`` execs ``sgc`` in its own process, which then inherits pip's CPU time."""


def cpu_seconds() -> float:
    """CPU time of this process and its waited-for children (ffmpeg), user + system, without
    the children of whatever ran in this process before the command (see above)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system - _EARLIER_CHILDREN


def ball_indices(scenario: Any) -> list[int]:
    """Index in ``scenario.props`` of each rod's red ball (``rod_gold`` -> ``ball_gold``)."""
    names = [p.name for p in scenario.props]
    return [names.index(f"ball_{b.name[4:]}") for b in scenario.bodies]


def pierce_times(
    scenario: Any, times: Sequence[float], tips: np.ndarray
) -> list[float | None]:
    """When each rod pierced its ball: None if its tip never came within the ball's radius of
    the ball's centre, else the tick of closest approach within the first such contact.

    ``tips``: (ticks, rods, 3) tip positions at ``times``. The expert meets each ball's centre
    on the tick of the pierce goal (1.2 s), so its balls are carried from exactly then."""
    out: list[float | None] = []
    for b, k in enumerate(ball_indices(scenario)):
        ball = scenario.props[k]
        distance = np.array([np.linalg.norm(tips[i, b] - ball.position_at(t))
                             for i, t in enumerate(times)])  # fmt: skip
        inside = distance <= ball.size[0]
        if not inside.any():
            out.append(None)
            continue
        first = int(np.argmax(inside))
        last = first + int(np.argmin(inside[first:])) if not inside[first:].all() else len(times)
        out.append(float(times[first + int(np.argmin(distance[first:last]))]))
    return out


class BallCarry:
    """Where the demo draws each prop: a red ball its rod pierced rides on the rod from the
    pierce on (sliding from the tip to the middle in :data:`BALL_SLIDE` s), every other prop
    is where its own path puts it. ``pierce``: when each rod pierced its ball (None: never;
    see :func:`pierce_times`). The video and the glTF file draw the same places."""

    def __init__(self, scenario: Any, pierce: Sequence[float | None]) -> None:
        from sgc_env.scenes import three_rods

        if len(pierce) != len(scenario.bodies):
            raise ValueError(f"pierce: expected one time per rod, got {len(pierce)}")
        self.props = scenario.props
        self.ball_index = ball_indices(scenario)
        self.tip = np.asarray(three_rods.TIP, float)
        self.pierce = list(pierce)

    def positions(self, now: float, positions: Sequence[Sequence[float]],
                  orientations: Sequence[Sequence[float]]) -> list[np.ndarray]:  # fmt: skip
        """Every prop's drawn position at time ``now``, the rods posed as the env has them."""
        props = [np.asarray(p.position_at(now), float) for p in self.props]
        for k, pierced, position, orientation in zip(self.ball_index, self.pierce, positions,
                                                     orientations, strict=True):  # fmt: skip
            if pierced is None or now < pierced:
                continue
            slide = min((now - pierced) / BALL_SLIDE, 1.0)
            along = self.tip * (1.0 - slide * slide * (3.0 - 2.0 * slide))
            axis = np.asarray(pybullet.getMatrixFromQuaternion(orientation)).reshape(3, 3)
            props[k] = np.asarray(position, float) + axis @ along
        return props


class DemoScene:
    """The demo's render world (thick rod shells, the bullseye board) with the props where
    :class:`BallCarry` puts them."""

    def __init__(self, scenario: Any, pierce: Sequence[float | None]) -> None:
        self.carry = BallCarry(scenario, pierce)
        self.world = RenderWorld(scenario, ROD_DRAW_RADIUS)
        self.client = self.world.client
        self.ball_uids = [self.world.prop_uids[k] for k in self.carry.ball_index]
        self.rods = self.world.body_uids

    def update(self, now: float, positions: Sequence[Sequence[float]],
               orientations: Sequence[Sequence[float]]) -> list[Caster]:  # fmt: skip
        """Pose rods (as the env has them) and props for time ``now``; the shadow casters."""
        return self.world.update(positions, orientations,
                                 self.carry.positions(now, positions, orientations))  # fmt: skip

    def close(self) -> None:
        self.world.close()


def demo_policy(options: DemoOptions, env: Any) -> Any:
    """The policy that flies the demo; a ValueError (exit 2 in the CLI) if the spec is unknown
    or a model file does not fit the three-rod env (checked before anything is unpickled)."""
    from baselines.controllers.expert import SGCExpert
    from baselines.policies import make_policy

    if options.policy == "expert":  # as before --policy existed: the same outputs, bit for bit
        return SGCExpert(env, end_rule=options.end_rule)
    return make_policy(options.policy, env, seed=0, trust_model=options.trust_model)


def open_demo(options: DemoOptions) -> tuple[str, Any, Any]:
    """The id of the paper's scene (:data:`ENV_ID`), that env (open: the caller closes it) and
    the policy on it; raises :func:`demo_policy`'s ValueError when the policy does not fit."""
    import gymnasium as gym

    env = gym.make(ENV_ID)
    try:
        return ENV_ID, env, demo_policy(options, env)
    except BaseException:
        env.close()
        raise


def demo_env_id(options: DemoOptions) -> str:
    """The version of the paper's scene the policy flies (:func:`open_demo`)."""
    env_id, env, _ = open_demo(options)
    env.close()
    return env_id


def check_policy(options: DemoOptions) -> None:
    """Raise :func:`demo_policy`'s ValueError now, before any output or progress bar."""
    demo_env_id(options)


def run_demo(
    options: DemoOptions, progress: Callable[[int, int], None] | None = None
) -> DemoResult:
    """Run, score and render the demo; ``progress(done, total)`` is called every tick, of the
    episode and then of the drawing (``total`` counts both)."""
    from baselines.evaluation.harness import (
        goal_rows,
        run_episode,
        summarize,
        write_goals_csv,
        write_summary_json,
    )

    started = cpu_seconds()
    env_id, env, policy = open_demo(options)
    options.out.mkdir(parents=True, exist_ok=True)
    base: Any = env.unwrapped  # the SGCEnv: scenario, sim, max_steps
    scenario = base.scenario
    passes = 2 if options.video else 1
    total = passes * base.max_steps
    ticks: list[Mapping[str, Any]] = []

    def on_step(env_: Any, step: int, info: Mapping[str, Any]) -> None:
        ticks.append(info)
        if progress is not None:
            progress(step, total)

    try:
        record = run_episode(policy, env, seed=0, keep_infos=True, on_step=on_step)
    finally:
        env.close()

    result = DemoResult(label=options.label, scenario=scenario)
    result.motion = demo_motion(scenario, ticks, result.label)
    if options.gltf:
        result.files[GLTF_FILE] = write_glb(options.out / GLTF_FILE, scenario, [result.motion],
                                            rod_radius=ROD_DRAW_RADIUS)  # fmt: skip
        result.files[VIEWER_PAGE] = write_viewer(options.out, GLTF_FILE)
    if options.video:
        drawn = None if progress is None else (lambda step: progress(base.max_steps + step, total))
        frame_every = round(base.control_frequency / VIDEO_FPS)
        result.frames, result.frame_times = _draw(scenario, ticks, options, frame_every, drawn)
    rows = goal_rows(record, env_id, result.label)
    result.summary = summarize([record], rows)
    result.files["goals.csv"] = write_goals_csv(rows, options.out / "goals.csv")
    result.files["summary.json"] = write_summary_json(result.summary, options.out / "summary.json")
    result.per_rod = _per_rod(record, rows, scenario)
    per_rod_path = options.out / "rods.json"
    per_rod_path.write_text(json.dumps(result.per_rod, indent=2))
    result.files["rods.json"] = per_rod_path
    result.files.update(_plots(record, scenario, options.out))
    if result.frames:
        result.files.update(_videos(result.frames, result.frame_times, options))
    result.cpu_s = cpu_seconds() - started
    return result


def demo_motion(scenario: Any, ticks: Sequence[Mapping[str, Any]], label: str) -> Motion:
    """The flight of the reset's and every step's ``ticks``, with the props where the video
    draws them (:class:`BallCarry`)."""
    times = [float(info.get("time", 0.0)) for info in ticks]
    tips = np.stack([np.asarray(info["point_position"], float) for info in ticks])
    carry = BallCarry(scenario, pierce_times(scenario, times, tips))
    props = np.array([carry.positions(now, info["body_position"], info["body_orientation"])
                      for now, info in zip(times, ticks, strict=True)])  # fmt: skip
    return motion_of(label, ticks, props.reshape(len(times), len(scenario.props), 3))


def _draw(
    scenario: Any, ticks: Sequence[Mapping[str, Any]], options: DemoOptions, frame_every: int,
    progress: Callable[[int], None] | None,
) -> tuple[list[np.ndarray], list[float]]:  # fmt: skip
    """The video's frames (one every ``frame_every`` ticks) and their times."""
    times = [float(info.get("time", 0.0)) for info in ticks]
    tips = [np.asarray(info["point_position"], float) for info in ticks]
    scene = DemoScene(scenario, pierce_times(scenario, times, np.stack(tips)))
    nails = [np.array([g.nail for g in b.goals if g.nail is not None]) for b in scenario.bodies]
    painter = Painter(scene.client, [b.color for b in scenario.bodies], nails)
    frames: list[np.ndarray] = []
    frame_times: list[float] = []
    try:
        for step, (now, info) in enumerate(zip(times, ticks, strict=True)):
            if step % frame_every == 0:
                casters = scene.update(now, info["body_position"], info["body_orientation"])
                view = camera_at(now, options.width, options.height)
                trails = _trails(tips[: step + 1], times[: step + 1], now)
                frames.append(painter.frame(view, trails, casters, now))
                frame_times.append(now)
            if progress is not None:
                progress(step)
    finally:
        scene.close()
    return frames, frame_times


def _trails(tips: list[np.ndarray], times: list[float], now: float) -> list[Trail]:
    """The last ``TRAIL_SECONDS`` of every tip, one sample per control tick."""
    first = int(np.searchsorted(times, now - TRAIL_SECONDS))
    recent = np.stack(tips[first:])
    stamps = np.asarray(times[first:])
    return [Trail(recent[:, b], stamps) for b in range(recent.shape[1])]


_SMOOTHNESS_KEYS = (
    "ldlj_track", "acceleration_peak", "acceleration_kink",
    "angular_ldlj_track", "angular_acceleration_peak", "angular_acceleration_kink",
)  # fmt: skip
"""The harness's whole-track smoothness figures each rod's row carries (docs/metrics.md)."""


def _per_rod(
    record: Any, rows: Sequence[Mapping[str, Any]], scenario: Any
) -> list[dict[str, Any]]:
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
                "position_error_max_m": max(position) if position else None,
                "orientation_error_max_rad": max(orientation) if orientation else None,
                "closest_approach_offset_max_s": max(offsets) if offsets else None,
                "sparc_track": card.get("sparc_track"),
                "goal_speed_ratio_min": card.get("goal_speed_ratio_min"),
                "speed_minima": card.get("speed_minima_total"),
                **{key: card.get(key) for key in _SMOOTHNESS_KEYS},
                "goals_met": card.get("goals_met"),
            }
        )
    return out


def _plots(record: Any, scenario: Any, out: Path) -> dict[str, Path]:
    from baselines.figures.plots import (
        plot_deviation_components,
        plot_speed_profile,
        trajectory_arrays,
    )

    traj = trajectory_arrays(record.infos, record.initial_info)
    names = [b.name for b in scenario.bodies]
    colors = [tuple(b.color[:3]) for b in scenario.bodies]
    return {
        "deviation.png": plot_deviation_components(
            traj, record.goals, out / "deviation.png",
            title="three rods: deviation of each tip (D) and orientation (phi), goal times dotted",
            names=names, colors=colors, layout=None,
        ),
        "speed.png": plot_speed_profile(
            traj, record.goals, out / "speed.png", names=names, colors=colors, layout=None
        ),
    }  # fmt: skip


def _videos(frames: list[Any], times: list[float], options: DemoOptions) -> dict[str, Path]:
    import imageio.v2 as imageio

    mp4 = write_mp4(options.out / "three_rods.mp4", frames)
    gif = options.out / "three_rods.gif"
    step = options.gif_scale
    small = [cv2.resize(f, (f.shape[1] // step, f.shape[0] // step), interpolation=cv2.INTER_AREA)
             for f in frames[::2]]  # fmt: skip
    write_gif(gif, small, gif_durations(len(small), VIDEO_FPS / 2))
    plates = options.out / "plates.png"
    imageio.imwrite(plates, plate_sheet(frames, times))
    return {"three_rods.mp4": mp4, "three_rods.gif": gif, "plates.png": plates}


def write_mp4(path: Path, frames: Sequence[np.ndarray]) -> Path:
    """``frames`` as an H.264 MP4 at :data:`VIDEO_FPS` (real time); ``path``."""
    import imageio.v2 as imageio

    imageio.mimwrite(path, list[Any](frames), fps=VIDEO_FPS, codec="libx264", quality=7,
                     macro_block_size=4, ffmpeg_params=["-preset", "veryfast"])  # fmt: skip
    return path


def plate_sheet(frames: Sequence[np.ndarray], times: Sequence[float]) -> np.ndarray:
    """Eight frames nearest :data:`PLATE_TIMES`, two rows of four, each titled."""
    h, w = frames[0].shape[:2]
    scale = min(1.0, 480.0 / w)
    tw, th, band = int(w * scale), int(h * scale), 26
    sheet = np.full((2 * (th + band), 4 * tw, 3), 255, np.uint8)
    for k, want in enumerate(PLATE_TIMES):
        i = int(np.argmin(np.abs(np.asarray(times) - want)))
        row, col = divmod(k, 4)
        y, x = row * (th + band), col * tw
        sheet[y + band : y + band + th, x : x + tw] = cv2.resize(
            frames[i], (tw, th), interpolation=cv2.INTER_AREA
        )
        cv2.putText(sheet, f"Plate {k + 1}   t = {times[i]:.2f} s", (x + 8, y + 18),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.5, (30, 30, 30), 1, cv2.LINE_AA)  # fmt: skip
    return sheet
