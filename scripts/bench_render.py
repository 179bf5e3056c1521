"""CPU time per frame of ``env.render()`` and of the demo, and of the renderer options
PyBullet offers here, as ratios.

Usage: .venv/bin/python scripts/bench_render.py [--frames 12] [--width 960] [--height 540]

First ``env.render()`` of ``SGCThreeRods-v2`` at its default 640x480 (fixed camera) during an
expert episode, against a bare TinyRenderer frame of the env's own physics client (no floor,
PyBullet's default look) of the same size through the same camera, both in this run; the
issue's budget is 60 ms of CPU per frame. Then the demo's scene at t = 2 s through the demo's
camera at ``--width`` x ``--height``. Measured with time.process_time (the machine is shared,
wall time is not a measure), each row the mean over ``--frames``:

* TinyRenderer with a floor body (a 600 m box) under the bodies, plain and with ``shadow=1``;
* TinyRenderer without a floor body (what the demo renders) and the demo's whole frame
  (that render plus sky, floor, shadows, trails and nails, ``DemoPainter.frame``);
* the EGL renderer plugin (``eglRenderer``), run in a child process because a loaded plugin
  takes over every later ``getCameraImage`` of that process; its own threads' CPU counts
  (``os.times`` of the child). On a machine without EGL the row says why it did not run.

The reference is the plain TinyRenderer frame with a floor, measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from typing import Any

import numpy as np

EGL_CHILD = r"""
import json, os, pkgutil, sys, time
import numpy as np, gymnasium as gym
import sgc_env
from sgc_env.simulator import pybullet as pb
from baselines.figures.demo_camera import camera_at
w, h, n = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
env = gym.make("SGCThreeRods-v2"); base = env.unwrapped
loader = pkgutil.get_loader("eglRenderer")
if loader is None:
    print(json.dumps({"error": "no eglRenderer module"})); sys.exit()
# the plugin only sees visual shapes created after it is loaded
plugin = pb.loadPlugin(loader.get_filename(), "_eglRendererPlugin",
                       physicsClientId=base.sim.client)
if plugin < 0:
    print(json.dumps({"error": "loadPlugin failed"})); sys.exit()
env.reset(seed=0)
for b in base.scenario.bodies:  # the demo's rod shells, here in the physics client
    shell = pb.createVisualShape(pb.GEOM_CYLINDER, radius=0.075, length=float(b.size[0]),
                                 rgbaColor=list(b.color), physicsClientId=base.sim.client)
    pb.createMultiBody(0.0, -1, shell, base.sim.body_states([base.sim.bodies[b.name].uid])[0][0],
                       physicsClientId=base.sim.client)
floor = pb.createVisualShape(pb.GEOM_BOX, halfExtents=[300.0, 300.0, 0.02],
                             rgbaColor=[0.62, 0.68, 0.62, 1.0], physicsClientId=base.sim.client)
pb.createMultiBody(0.0, -1, floor, [0.0, 0.0, -0.02], physicsClientId=base.sim.client)
view = camera_at(2.0, w, h)
def cpu():
    t = os.times(); return t.user + t.system
pb.getCameraImage(w, h, view.view, view.projection, physicsClientId=base.sim.client)
start = cpu()
for _ in range(n):
    pb.getCameraImage(w, h, view.view, view.projection, shadow=1,
                      renderer=pb.ER_BULLET_HARDWARE_OPENGL, physicsClientId=base.sim.client)
seconds = (cpu() - start) / n
if len(sys.argv) > 4:
    import imageio.v2 as imageio
    rgba = pb.getCameraImage(w, h, view.view, view.projection, shadow=1,
                             physicsClientId=base.sim.client)[2]
    imageio.imwrite(sys.argv[4], np.reshape(rgba, (h, w, 4))[:, :, :3].astype(np.uint8))
print(json.dumps({"egl_shadow": seconds}))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--width", type=int, default=960)
    parser.add_argument("--height", type=int, default=540)
    parser.add_argument("--images", default=None, metavar="DIR",
                        help="also write one frame per renderer here, to compare the looks")
    args = parser.parse_args()

    import gymnasium as gym

    import sgc_env  # noqa: F401  (registers the ids)
    from baselines.controllers.expert import SGCExpert
    from baselines.figures.demo import DemoScene
    from baselines.figures.demo_camera import camera_at
    from sgc_env.render import Painter, Trail
    from sgc_env.scenes import three_rods
    from sgc_env.simulator import pybullet as pb

    def per_frame(call) -> float:
        call()
        start = time.process_time()
        for _ in range(n):
            call()
        return (time.process_time() - start) / n

    n = args.frames
    env_rows = _env_render(n, per_frame, pb, SGCExpert)
    w, h = args.width, args.height
    env = gym.make("SGCThreeRods-v2")
    _, info = env.reset(seed=0)
    base: Any = env.unwrapped  # the SGCEnv
    pierced = [three_rods.PIERCE_TIME] * len(base.scenario.bodies)  # as the expert pierces
    scene = DemoScene(base.scenario, pierced)
    client = scene.client
    casters = scene.update(2.0, info["body_position"], info["body_orientation"])
    view = camera_at(2.0, w, h)

    def tiny(**kw):
        return lambda: pb.getCameraImage(w, h, view.view, view.projection,
                                         renderer=pb.ER_TINY_RENDERER, physicsClientId=client,
                                         **kw)  # fmt: skip

    rows = {"tiny, no floor body (the demo's render)": per_frame(tiny())}
    nails = [np.array([g.nail for g in b.goals]) for b in base.scenario.bodies]
    painter = Painter(client, [b.color for b in base.scenario.bodies], nails)
    trail = [Trail(np.array([[-6.0, 0.0, 3.0], [-5.0, 0.0, 3.2]]), np.array([1.9, 2.0]))] * 3
    def moving_camera_frame():
        painter.forget_view()  # the demo's camera moves every frame: no per-view cache
        return painter.frame(view, trail, casters, 2.0)

    rows["demo frame: that render + sky, floor, shadows, trails, nails"] = per_frame(
        moving_camera_frame
    )
    if args.images:
        import imageio.v2 as imageio

        os.makedirs(args.images, exist_ok=True)
        imageio.imwrite(os.path.join(args.images, "demo_frame.png"),
                        painter.frame(view, trail, casters, 2.0))  # fmt: skip
    floor = pb.createVisualShape(pb.GEOM_BOX, halfExtents=[300.0, 300.0, 0.02],
                                 rgbaColor=[0.62, 0.68, 0.62, 1.0], physicsClientId=client)
    pb.createMultiBody(0.0, -1, floor, [0.0, 0.0, -0.02], physicsClientId=client)
    reference = per_frame(tiny())
    rows["tiny with a floor body (reference)"] = reference
    rows["tiny with a floor body, shadow=1"] = per_frame(tiny(shadow=1, lightDirection=[1, -1, 3]))
    if args.images:
        for name, kw in (("tiny_shadow", {"shadow": 1, "lightDirection": [1, -1, 3]}),
                         ("tiny_plain", {})):  # fmt: skip
            rgba = tiny(**kw)()[2]
            imageio.imwrite(os.path.join(args.images, f"{name}.png"),
                            np.reshape(rgba, (h, w, 4))[:, :, :3].astype(np.uint8))  # fmt: skip
    env.close()
    scene.close()

    child = subprocess.run(
        [sys.executable, "-c", EGL_CHILD, str(w), str(h), str(n),
         *([os.path.join(args.images, "egl_shadow.png")] if args.images else [])],
        capture_output=True, text=True, env={**os.environ}, timeout=600,
    )  # fmt: skip
    lines = [ln for ln in child.stdout.splitlines() if ln.startswith("{")]
    egl: dict[str, Any] = (
        json.loads(lines[-1]) if lines else {"error": child.stderr.strip()[-200:]}
    )

    (ew, eh), env_reference = env_rows[0], env_rows[1][1]
    print(f"env.render() of SGCThreeRods-v2, {ew}x{eh}, fixed camera, mean of {n} frames of an "
          f"expert episode, CPU s per frame (ratio to the bare frame)")  # fmt: skip
    for name, seconds in env_rows[1:]:
        print(f"  {name:62s} {seconds:7.4f}  ({seconds / env_reference:5.2f}x)")
    print(f"  budget 0.060 s: {'within' if env_rows[-1][1] <= 0.060 else 'OVER'}")
    print()
    print(f"the demo's scene, {w}x{h}, mean of {n} frames, CPU s per frame (ratio to the "
          f"reference)")  # fmt: skip
    for name, seconds in rows.items():
        print(f"  {name:62s} {seconds:7.4f}  ({seconds / reference:5.2f}x)")
    if "error" in egl:
        print(f"  EGL plugin: did not run ({egl['error']})")
    else:
        s = float(egl["egl_shadow"])
        print(f"  {'EGL plugin (llvmpipe), shadow=1, child process':62s} {s:7.4f}  "
              f"({s / reference:5.2f}x)")  # fmt: skip


def _env_render(n: int, per_frame, pb, expert_class) -> list:
    """[(width, height), (bare row), (env.render row)] on SGCThreeRods-v2 at its defaults: the
    frames are taken along an expert episode (every 4th tick), so trails and poses vary."""
    import gymnasium as gym

    env = gym.make("SGCThreeRods-v2", render_mode="rgb_array")
    expert = expert_class(env)
    obs, _ = env.reset(seed=0)
    base: Any = env.unwrapped
    for _ in range(60):  # into the flight
        obs, *_ = env.step(expert.predict(obs, deterministic=True)[0])
        env.render()

    def advance() -> None:
        nonlocal obs
        for _ in range(4):
            obs, *_ = env.step(expert.predict(obs, deterministic=True)[0])

    w, h = base.width, base.height
    view = base.camera_view()
    bare = per_frame(lambda: pb.getCameraImage(w, h, view.view, view.projection,
                                               renderer=pb.ER_TINY_RENDERER,
                                               physicsClientId=base.sim.client))  # fmt: skip
    spent = 0.0
    for _ in range(n):  # only the render is timed
        advance()
        start = time.process_time()
        env.render()
        spent += time.process_time() - start
    rendering = spent / n
    env.close()
    return [(w, h), ("bare TinyRenderer frame of the physics client (reference)", bare),
            ("env.render(): the demo's look, fixed camera", rendering)]


if __name__ == "__main__":
    main()
