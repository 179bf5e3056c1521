"""The glTF files in the field's own tools (slow: each needs a tool from outside PyPI).

- Khronos glTF-Validator reports no error on the demo's file and on a rollout of every id:
  ``npm install --prefix DIR gltf-validator@2.0.0-dev.3.10`` (CI does, see ``.ci/run``);
- Blender imports the demo's file with the three rods keyframed where the env put them:
  ``apt-get install blender python3-numpy``;
- the viewer page shows the three rods in headless Chromium:
  ``apt-get install chromium`` and ``npm install --prefix DIR three@0.187.0``.

Run with ``SGC_NODE_MODULES=DIR/node_modules .venv/bin/python -m pytest -m slow`` on this file;
a missing tool fails the test with the line that installs it.
"""

from __future__ import annotations

import functools
import http.server
import json
import os
import shutil
import subprocess
import threading
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from baselines.cli.main import main
from baselines.figures.demo import GLTF_FILE

pytestmark = pytest.mark.slow
HERE = Path(__file__).resolve().parent
VALIDATE = (
    "const v = require(process.argv[1] + '/gltf-validator'); const fs = require('fs');"
    "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2])))"
    ".then(r => console.log(JSON.stringify(r.issues)))"
)


def _node_modules(package: str) -> Path:
    folder = Path(os.environ.get("SGC_NODE_MODULES", "node_modules"))
    if not (folder / package).is_dir():
        pytest.fail(f"no {package} in {folder}: npm install --prefix DIR {package} and set "
                    "SGC_NODE_MODULES=DIR/node_modules")  # fmt: skip
    return folder


def _tool(name: str, install: str) -> str:
    found = shutil.which(name)
    if found is None:
        pytest.fail(f"{name} is not installed: {install}")
    return found


@pytest.fixture(scope="module")
def demo_glb(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    assert main(["demo", "--out", str(out), "--no-video"]) == 0
    return out / GLTF_FILE


def _issues(path: Path) -> dict:
    modules = _node_modules("gltf-validator")
    node = _tool("node", "apt-get install nodejs")
    run = subprocess.run([node, "-e", VALIDATE, str(modules), str(path)], capture_output=True,
                         text=True, check=True)  # fmt: skip
    return json.loads(run.stdout)


def test_validator_finds_no_error_in_the_demo(demo_glb):
    issues = _issues(demo_glb)
    assert issues["numErrors"] == 0, issues["messages"]
    assert issues["numWarnings"] == 0, issues["messages"]


@pytest.mark.parametrize("env_id", sorted(k for k in gym.registry if k.startswith("SGC")))
def test_validator_finds_no_error_in_a_rollout_of_every_id(env_id, tmp_path):
    out = tmp_path / "ro"
    argv = ["rollout", "--env", env_id, "--gltf", "--no-compare"]  # the expert: every goal
    assert main([*argv, "--out", str(out)]) == 0
    issues = _issues(out / "rollout.glb")
    assert issues["numErrors"] == 0, issues["messages"]


def test_blender_imports_the_three_rods_keyframed_where_the_env_put_them(demo_glb):
    blender = _tool("blender", "apt-get install blender python3-numpy")
    times = (0.4, 3.7, 8.65)
    run = subprocess.run(
        [blender, "-b", "--python", str(HERE / "blender_positions.py"), "--", str(demo_glb),
         "expert/rod_", "60", ",".join(map(str, times))],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    line = [row for row in run.stdout.splitlines() if row.startswith("POSITIONS ")]
    assert line, run.stdout[-2000:] + run.stderr[-2000:]
    objects = json.loads(line[0].removeprefix("POSITIONS "))
    from baselines.controllers.expert import SGCExpert
    from baselines.evaluation.harness import run_episode

    env = gym.make("SGCThreeRods-v2")
    record = run_episode(SGCExpert(env), env, seed=0, keep_infos=True)
    names = [b.name for b in env.unwrapped.scenario.bodies]
    assert sorted(objects) == sorted(f"expert/{n}" for n in names)
    infos = [record.initial_info, *record.infos]
    for b, name in enumerate(names):
        assert objects[f"expert/{name}"]["keyframed"]
        for t in times:
            env_at = infos[round(t * 60)]["body_position"][b]  # Blender's world is z-up again
            np.testing.assert_allclose(objects[f"expert/{name}"]["at"][str(t)], env_at,
                                       rtol=0, atol=1e-5)  # fmt: skip


def test_the_viewer_page_shows_the_three_rods_in_chromium(demo_glb, tmp_path):
    chromium = _tool("chromium", "apt-get install chromium")
    modules = _node_modules("three")
    site = demo_glb.parent
    (site / "node_modules").symlink_to(modules.resolve(), target_is_directory=True)
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    shot = tmp_path / "shot.png"
    try:
        subprocess.run(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--disable-background-networking",
             "--disable-component-update", "--disable-sync", "--no-first-run",
             f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=8000",
             "--window-size=1280,800", f"--screenshot={shot}",
             f"http://127.0.0.1:{server.server_port}/viewer.html?t=3.6"],
            capture_output=True, timeout=120, check=True,
        )  # fmt: skip
    finally:
        server.shutdown()
    import imageio.v2 as imageio

    image = imageio.imread(shot)[..., :3].astype(int)
    env = gym.make("SGCThreeRods-v2")
    env.reset(seed=0)
    for body in env.unwrapped.scenario.bodies:  # each rod's hue shows on some pixels
        want = np.asarray(body.color[:3]) * 255
        hue = want / np.linalg.norm(want)
        seen = image / np.maximum(np.linalg.norm(image, axis=-1, keepdims=True), 1)
        assert np.sum(np.sum(seen * hue, axis=-1) > 0.995) > 20, body.name
