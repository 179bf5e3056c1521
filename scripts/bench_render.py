"""CPU time per demo frame for the renderer options PyBullet offers here, as ratios.

Usage: .venv/bin/python scripts/bench_render.py [--frames 12] [--width 960] [--height 540]

The three-rod scene at t = 2 s through the demo's camera. Measured with time.process_time
(the machine is shared, wall time is not a measure), each row the mean over ``--frames``:

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

import numpy as np

EGL_CHILD = r"""
import json, os, pkgutil, sys, time
import numpy as np, gymnasium as gym
import sgc_env
from sgc_env.simulator import pybullet as pb
from baselines.cli.demo import DemoScene
from baselines.cli.demo_camera import camera_at
w, h, n = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
env = gym.make("SGCThreeRods-v0"); base = env.unwrapped
loader = pkgutil.get_loader("eglRenderer")
if loader is None:
    print(json.dumps({"error": "no eglRenderer module"})); sys.exit()
# the plugin only sees visual shapes created after it is loaded
plugin = pb.loadPlugin(loader.get_filename(), "_eglRendererPlugin",
                       physicsClientId=base.sim.client)
if plugin < 0:
    print(json.dumps({"error": "loadPlugin failed"})); sys.exit()
env.reset(seed=0)
scene = DemoScene(base.sim, base.scenario); scene.update(2.0)
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
    from baselines.cli.demo import DemoScene
    from baselines.cli.demo_camera import camera_at
    from baselines.cli.demo_view import DemoPainter, Trail
    from sgc_env.simulator import pybullet as pb

    w, h, n = args.width, args.height, args.frames
    env = gym.make("SGCThreeRods-v0")
    env.reset(seed=0)
    base = env.unwrapped
    client = base.sim.client
    scene = DemoScene(base.sim, base.scenario)
    casters = scene.update(2.0)
    view = camera_at(2.0, w, h)

    def per_frame(call) -> float:
        call()
        start = time.process_time()
        for _ in range(n):
            call()
        return (time.process_time() - start) / n

    def tiny(**kw):
        return lambda: pb.getCameraImage(w, h, view.view, view.projection,
                                         renderer=pb.ER_TINY_RENDERER, physicsClientId=client,
                                         **kw)  # fmt: skip

    rows = {"tiny, no floor body (the demo's render)": per_frame(tiny())}
    nails = [np.array([g.nail for g in b.goals]) for b in base.scenario.bodies]
    painter = DemoPainter(client, [b.color for b in base.scenario.bodies], nails)
    trail = [Trail(np.array([[-6.0, 0.0, 3.0], [-5.0, 0.0, 3.2]]), np.array([1.9, 2.0]))] * 3
    rows["demo frame: that render + sky, floor, shadows, trails, nails"] = per_frame(
        lambda: painter.frame(view, trail, casters, 2.0)
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

    child = subprocess.run(
        [sys.executable, "-c", EGL_CHILD, str(w), str(h), str(n),
         *([os.path.join(args.images, "egl_shadow.png")] if args.images else [])],
        capture_output=True, text=True, env={**os.environ}, timeout=600,
    )  # fmt: skip
    lines = [ln for ln in child.stdout.splitlines() if ln.startswith("{")]
    egl = json.loads(lines[-1]) if lines else {"error": child.stderr.strip()[-200:]}

    print(f"{w}x{h}, mean of {n} frames, CPU s per frame (ratio to the reference)")
    for name, seconds in rows.items():
        print(f"  {name:62s} {seconds:7.4f}  ({seconds / reference:5.2f}x)")
    if "error" in egl:
        print(f"  EGL plugin: did not run ({egl['error']})")
    else:
        s = egl["egl_shadow"]
        print(f"  {'EGL plugin (llvmpipe), shadow=1, child process':62s} {s:7.4f}  "
              f"({s / reference:5.2f}x)")  # fmt: skip


if __name__ == "__main__":
    main()
