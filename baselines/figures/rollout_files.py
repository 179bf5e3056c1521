"""The files of one ``sgc rollout``: trajectory arrays, the episode's scorecard, the plots
(the paper's Figures 1 and 2 side by side among them), the video and the glTF scene."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["write_rollout"]


def _save_npz(path: Path, traj: dict[str, Any], goals: list[list[Any]]) -> None:
    import numpy as np

    extra: dict[str, Any] = {}
    for b, body_goals in enumerate(goals):
        extra[f"goal_times_{b}"] = np.array([g.time for g in body_goals])
        extra[f"nails_{b}"] = np.array(
            [g.nail if g.nail is not None else (np.nan,) * 3 for g in body_goals], dtype=float
        )
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **traj, **extra)


def write_rollout(
    out: Path, env: Any, record: Any, title: str, policy: str, seed: int, compare: bool,
    frames: list[Any] | None, gltf: bool = False,
) -> None:  # fmt: skip
    """The trajectory, the scorecard, the plots, the video and (``gltf``) the glTF scene of
    one rollout, into ``out``."""
    from baselines.evaluation.harness import run_episode, write_summary_json
    from baselines.figures import plots
    from baselines.policies import make_policy, policy_label

    traj = plots.trajectory_arrays(record.infos or [], record.initial_info)
    _save_npz(out / "trajectory.npz", traj, record.goals)
    write_summary_json(record.card, out / "summary.json")
    if gltf:
        from sgc_env.export.gltf import motion_of, write_glb, write_viewer

        motion = motion_of(policy_label(policy), [record.initial_info, *(record.infos or [])])
        # the env holds this seed's scenario until the comparison below resets it again
        write_glb(out / "rollout.glb", env.unwrapped.scenario, [motion])
        write_viewer(out, "rollout.glb")
    plots.plot_deviation_components(traj, record.goals, out / "deviation.png", title)
    plots.plot_path_3d(traj, record.goals, out / "path3d.png", title)
    plots.plot_speed_profile(traj, record.goals, out / "speed.png", title)
    if compare:
        runs = {}
        for spec, method in (
            ("dynamic-constraints", "dynamic constraints (Fig. 1)"),
            ("expert", "sequential-goal constraints (Fig. 2)"),
        ):
            if spec == policy:
                runs[method] = traj
                continue
            other = run_episode(make_policy(spec, env), env, seed, keep_infos=True)
            runs[method] = plots.trajectory_arrays(other.infos or [], other.initial_info)
        plots.plot_method_comparison(runs, record.goals, out / "figure1_vs_2.png")
    if frames:
        import imageio

        fps = int(env.unwrapped.metadata.get("render_fps", 60))
        imageio.mimsave(out / "rollout.mp4", frames, fps=fps)
