"""``sgc demo --compare A,B``: two runs of the demo side by side in one video.

:func:`fly_demos` runs the demo for one policy or two; with two, each run's outputs go to a
folder of its label, beside ``compare.mp4`` and both scorecards in ``summary.json``.

The panels are the two runs' own frames (no second render): same camera and clock, since both
runs draw the same shots at the same ticks. A run that ended early (terminated) holds its last
frame. Each panel is labelled with its policy and the clock.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from pathlib import Path

import cv2
import numpy as np

from baselines.figures.demo import DemoOptions, DemoResult, run_demo, write_mp4

__all__ = ["COMPARE_GLTF", "COMPARE_VIDEO", "fly_demos", "side_by_side", "write_side_by_side"]

COMPARE_VIDEO = "compare.mp4"
COMPARE_GLTF = "compare.glb"
"""Both flights in one glTF scene: a group and an animation per policy, named by its label."""


def _caption(panel: np.ndarray, lines: Sequence[str]) -> np.ndarray:
    """``panel`` with ``lines`` written top left on a dark band (a copy)."""
    out = panel.copy()
    scale = max(0.35, min(1.0, panel.shape[1] / 960.0)) * 0.7
    step = int(28 * scale / 0.7)
    band = min(out.shape[0], step * len(lines) + 8)
    out[:band] = (out[:band] * 0.45).astype(np.uint8)
    for i, line in enumerate(lines):
        cv2.putText(out, line, (8, step * (i + 1)), cv2.FONT_HERSHEY_SIMPLEX, scale,
                    (255, 255, 255), 1, cv2.LINE_AA)  # fmt: skip
    return out


def side_by_side(left: DemoResult, right: DemoResult) -> list[np.ndarray]:
    """One frame per tick of the longer run: ``left`` and ``right`` next to each other."""
    if not left.frames or not right.frames:
        raise ValueError("compare: both runs need their video frames (not --no-video)")
    if left.frames[0].shape != right.frames[0].shape:
        raise ValueError("compare: the two runs were drawn at different sizes")
    count = max(len(left.frames), len(right.frames))
    times = left.frame_times if len(left.frames) == count else right.frame_times
    out = []
    for i in range(count):
        panels = []
        for run in (left, right):
            j = min(i, len(run.frames) - 1)
            held = " (ended)" if j < i else ""
            panels.append(_caption(run.frames[j], [run.label, f"t = {times[i]:.2f} s{held}"]))
        out.append(np.concatenate(panels, axis=1))
    return out


def write_side_by_side(left: DemoResult, right: DemoResult, out: Path) -> Path:
    """Write :func:`side_by_side` as an MP4 at the demo's frame rate (real time); its path."""
    return write_mp4(out / COMPARE_VIDEO, side_by_side(left, right))


def write_compare_glb(results: Sequence[DemoResult], path: Path) -> Path:
    """Every run's flight in one glTF scene of the paper's three rods (every version of the
    demo flies the same bodies, props and nails); ``path``."""
    from baselines.figures.demo import ROD_DRAW_RADIUS
    from sgc_env.export.gltf import write_glb

    motions = [r.motion for r in results if r.motion is not None]
    return write_glb(path, results[0].scenario, motions, rod_radius=ROD_DRAW_RADIUS)


def fly_demos(
    options: Sequence[DemoOptions],
    labels: Sequence[str],
    folder: Path,
    progress: Callable[[str], Callable[[int, int], None]],
) -> tuple[list[DemoResult], list[Path]]:
    """Run the demo of each option into ``folder`` (two: ``folder/<label>`` each, then the
    side-by-side video, both flights in one glTF scene and both scorecards); the results and
    every file written.
    ``progress(label)`` gives each run's ``progress(done, total)``."""
    from baselines.evaluation.harness import write_summary_json

    compare = len(options) > 1
    results = [
        run_demo(dataclasses.replace(o, out=folder / label if compare else folder), progress(label))
        for o, label in zip(options, labels, strict=True)
    ]
    files = [path for result in results for path in result.files.values()]
    if compare:
        files.append(write_side_by_side(results[0], results[1], folder))
        if all(o.gltf for o in options):
            from sgc_env.export.gltf import write_viewer

            files.append(write_compare_glb(results, folder / COMPARE_GLTF))
            files.append(write_viewer(folder, COMPARE_GLTF))
        summaries = {r.label: r.summary for r in results}
        files.append(write_summary_json(summaries, folder / "summary.json"))
    return results, files
