"""Every cap of :data:`sgc_env.scenario.caps.CAPS`, generated from the table: a file at the
cap loads (just under: works), one past it is refused with the cap in the message, fast
(just over: refused before the work). The shipped models, scenarios, recipes and
hyperparameter files all load under the caps.
"""

from __future__ import annotations

import io
import json
import time
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from sgc_env.scenario import ScenarioError, scenario_from_dict
from sgc_env.scenario.bounded import FileLimitError, load_json, read_bounded
from sgc_env.scenario.caps import CAPS, cap
from sgc_env.scenario.load import builtin_scenarios, load_scenario

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "baselines" / "checkpoints"
WORKSPACE = {"low": [-100.0, -100.0, -100.0], "high": [100.0, 100.0, 100.0]}


def _body(i: int = 0, goals: list | None = None) -> dict[str, Any]:
    return {"name": f"b{i}", "shape": "sphere", "size": [0.05], "position": [0.2 * i, 0.0, 1.0],
            "goals": goals or [{"nail": [0.2 * i, 0.5, 1.0], "time": 1.0}]}  # fmt: skip


def _scenario(**extra: Any) -> dict[str, Any]:
    return {"name": "caps", "workspace": WORKSPACE, "bodies": [_body()], **extra}


def _path_goal(path: dict[str, Any], samples: int = 10, time: float = 5.0) -> dict[str, Any]:
    return {"path": path, "samples": samples, "time": time}


# ---------------------------------------------------------------- one probe per cap


def _file_bytes(n: int, tmp: Path) -> None:
    path = tmp / "big.json"
    path.write_text('{"pad": "' + "x" * (n - 11) + '"}')
    assert path.stat().st_size == n
    load_json(read_bounded(path, "json"), str(path))


def _yaml_bytes(n: int, tmp: Path) -> None:
    head = "name: caps\nbodies: [{name: b, shape: sphere, size: [0.05], position: [0, 0, 1], " \
           "goals: [{nail: [0, 0.5, 1], time: 1.0}]}]\n#"  # fmt: skip
    path = tmp / "big.yaml"
    path.write_text(head + "x" * (n - len(head) - 1) + "\n")
    assert path.stat().st_size == n
    load_scenario(path)


def _nesting(n: int, tmp: Path) -> None:
    load_json("[" * n + "]" * n, "nesting")


def _data_nodes(n: int, tmp: Path) -> None:
    load_json("[" + ",".join(["0"] * (n - 1)) + "]", "nodes")  # the list and n - 1 numbers


def _bodies(n: int, tmp: Path) -> None:
    scenario_from_dict(_scenario(bodies=[_body(i) for i in range(n)]))


def _props(n: int, tmp: Path) -> None:
    props = [{"name": f"p{i}", "shape": "sphere", "size": [0.1], "position": [5.0, i, 1.0]}
             for i in range(n)]  # fmt: skip
    scenario_from_dict(_scenario(props=props))


def _goals(n: int, tmp: Path) -> None:
    full, rest = divmod(n, 1000)
    goals = [_path_goal({"curve": "line", "start": [0, 0, 1], "end": [0.1 * k + 0.1, 0, 1]},
                        1000, 150.0 * (k + 1)) for k in range(full)]  # fmt: skip
    goals += [{"nail": [0.0, 0.1 * j, 1.0]} for j in range(rest)]
    scenario_from_dict(_scenario(bodies=[_body(0, goals)]))


def _path_samples(n: int, tmp: Path) -> None:
    line = {"curve": "line", "start": [0, 0, 1], "end": [1, 0, 1]}
    scenario_from_dict(_scenario(bodies=[_body(0, [_path_goal(line, n, 100.0)])]))


def _helix_turns(n: int, tmp: Path) -> None:
    helix = {"curve": "helix", "center": [0, 0, 1], "radius": 0.1, "turns": n, "height": 0.5}
    scenario_from_dict(_scenario(bodies=[_body(0, [_path_goal(helix, 1000, 1000.0)])]))


def _polyline_points(n: int, tmp: Path) -> None:
    line = {"curve": "polyline", "waypoints": [[0.001 * k, 0.0, 1.0] for k in range(n)]}
    scenario_from_dict(_scenario(bodies=[_body(0, [_path_goal(line)])]))


def _prop_waypoints(n: int, tmp: Path) -> None:
    prop = {"name": "p", "shape": "sphere", "size": [0.1],
            "waypoints": [{"time": 0.01 * k, "position": [2.0, 0.0, 1.0]} for k in range(n)]}
    scenario_from_dict(_scenario(props=[prop]))


def _sim_frequency(n: int, tmp: Path) -> None:
    from baselines.common.env_kwargs import check_env_kwargs

    check_env_kwargs("SGCPoint-v1", {"sim_frequency": n, "control_frequency": 1000}, "kwargs")


def _n_envs(n: int, tmp: Path) -> None:
    from baselines.agents.hyperparams import load_hyperparams

    (tmp / "ppo.yml").write_text(f"SGCPoint-v1: {{n_timesteps: 64, policy: MlpPolicy, "
                                 f"n_envs: {n}}}\n")  # fmt: skip
    load_hyperparams("ppo", "SGCPoint-v1", tmp)


def _net(net_arch: list[int], tmp: Path) -> None:
    from baselines.agents.hyperparams import load_hyperparams

    (tmp / "ppo.yml").write_text(f"SGCPoint-v1: {{n_timesteps: 64, policy: MlpPolicy, "
                                 f"policy_kwargs: 'dict(net_arch={net_arch})'}}\n")  # fmt: skip
    load_hyperparams("ppo", "SGCPoint-v1", tmp)


def _net_parameters(n: int, tmp: Path) -> None:
    from baselines.common.network_caps import check_net_arch

    check_net_arch([1], "net_arch", inputs=n)  # n inputs to one unit: n weights


def _clean_zip(tmp: Path) -> Path:
    gym = pytest.importorskip("gymnasium")
    from stable_baselines3 import PPO

    import sgc_env  # noqa: F401

    env = gym.make("SGCPoint-v1")
    path = tmp / "clean.zip"
    PPO("MlpPolicy", env, n_steps=64, batch_size=64, device="cpu",
        policy_kwargs={"net_arch": [8]}).save(path)  # fmt: skip
    env.close()
    return path


def _load_model(path: Path) -> None:
    import gymnasium as gym

    from baselines.models.model_files import load_sb3_model

    env = gym.make("SGCPoint-v1")
    try:
        load_sb3_model(path, env=env)
    finally:
        env.close()


def _with_extra(clean: Path, target: Path, extra: dict[str, int]) -> Path:
    """``clean`` plus members of zeros (name -> size), written in chunks."""
    with zipfile.ZipFile(clean) as zin, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as z:
        for info in zin.infolist():
            z.writestr(info, zin.read(info.filename))
        for name, size in extra.items():
            with z.open(name, "w", force_zip64=True) as member:
                for start in range(0, size, 1 << 24):
                    member.write(bytes(min(1 << 24, size - start)))
    return target


def _model_file_bytes(n: int, tmp: Path) -> None:
    blob = _clean_zip(tmp).read_bytes()
    path = tmp / "padded.zip"
    with path.open("wb") as fh:  # a zip may start after other bytes (a hole, here)
        fh.truncate(n - len(blob))
        fh.seek(n - len(blob))
        fh.write(blob)
    assert path.stat().st_size == n
    _load_model(path)


def _zip_members(n: int, tmp: Path) -> None:
    clean = _clean_zip(tmp)
    with zipfile.ZipFile(clean) as z:
        own = len(z.infolist())
    _load_model(_with_extra(clean, tmp / "m.zip", {f"n{i}.txt": 1 for i in range(n - own)}))


def _zip_member_bytes(n: int, tmp: Path) -> None:
    _load_model(_with_extra(_clean_zip(tmp), tmp / "m.zip", {"notes.txt": n}))


def _demos(tmp: Path, rows: int) -> Path:
    path = tmp / "d.npz"
    obs = np.zeros((rows, 1), np.float32)
    np.savez(path, observations=obs, actions=obs, rewards=obs[:, 0],
             terminations=np.zeros(rows, bool), truncations=np.zeros(rows, bool),
             episode_starts=np.ones(rows, bool), seeds=np.arange(1),
             env_id=np.array("SGCPoint-v1"), env_kwargs=np.array("{}"), pushes=np.array("{}"),
             format_version=np.array(1))  # fmt: skip
    return path


def _demo_rows(n: int, tmp: Path) -> None:
    from baselines.agents.demos import load_demos

    assert len(load_demos(_demos(tmp, n))) == n


def _npz_array_bytes(n: int, tmp: Path) -> None:
    """An npz whose one array is ``n`` bytes (only the headers are read)."""
    from baselines.common.bounded_npz import npz_shapes

    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "|u1", "fortran_order": False,
                                                  "shape": (n,)})  # fmt: skip
    path = tmp / "a.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z, \
            z.open("a.npy", "w", force_zip64=True) as member:  # fmt: skip
        member.write(header.getvalue())
        for start in range(0, n, 1 << 24):
            member.write(bytes(min(1 << 24, n - start)))
    assert npz_shapes(path, "npz")["a"][0] == (n,)


PROBES: dict[str, Callable[[int, Path], None]] = {
    "file_bytes": _file_bytes, "yaml_bytes": _yaml_bytes, "nesting": _nesting,
    "data_nodes": _data_nodes,
    "bodies": _bodies, "props": _props, "goals": _goals, "path_samples": _path_samples,
    "helix_turns": _helix_turns, "polyline_points": _polyline_points,
    "prop_waypoints": _prop_waypoints, "sim_frequency": _sim_frequency, "n_envs": _n_envs,
    "model_file_bytes": _model_file_bytes, "zip_members": _zip_members,
    "zip_member_bytes": _zip_member_bytes,
    "net_width": lambda n, tmp: _net([n], tmp), "net_layers": lambda n, tmp: _net([8] * n, tmp),
    "net_parameters": _net_parameters, "demo_rows": _demo_rows,
    "npz_array_bytes": _npz_array_bytes,
}  # fmt: skip
"""Cap -> a loader of an input asking for ``n`` of what the cap counts, through the code
that checks it."""

SB3_CAPS = {"sim_frequency", "n_envs", "model_file_bytes", "zip_members", "zip_member_bytes",
            "net_width", "net_layers", "net_parameters", "demo_rows"}  # fmt: skip


def test_every_cap_has_a_probe() -> None:
    assert set(PROBES) == set(CAPS)


def _needs(name: str) -> None:
    if name in SB3_CAPS:
        pytest.importorskip("stable_baselines3")


@pytest.mark.parametrize("name", sorted(CAPS))
def test_at_the_cap_it_works(name: str, tmp_path: Path) -> None:
    _needs(name)
    PROBES[name](cap(name), tmp_path)


@pytest.mark.parametrize("name", sorted(CAPS))
def test_past_the_cap_it_is_refused_fast(name: str, tmp_path: Path) -> None:
    _needs(name)
    started = time.perf_counter()
    with pytest.raises(ValueError) as err:
        PROBES[name](cap(name) + 1, tmp_path)
    message = str(err.value)
    assert f"at most {cap(name)}" in message or f"[1, {cap(name)}]" in message, message
    assert "\n" not in message
    assert time.perf_counter() - started < 10.0


# ---------------------------------------------------------------- shipped files load


def test_builtin_scenarios_load() -> None:
    names = builtin_scenarios()
    assert len(names) >= 4
    for name in names:
        assert load_scenario(name).bodies


def test_shipped_recipes_and_hyperparameters_load() -> None:
    pytest.importorskip("stable_baselines3")
    from baselines.agents.hyperparams import ALGORITHMS, load_hyperparams
    from baselines.benchmark.grid import load_recipes
    from sgc_env.scenario.bounded import load_yaml, read_text

    recipes = sorted((ROOT / "benchmarks").glob("*.yml"))
    assert recipes
    for path in recipes:
        assert load_recipes(path)
    folders = [None, ROOT / "benchmarks" / "zoo",
               *sorted(p for p in (ROOT / "benchmarks" / "hyperparams").iterdir())]  # fmt: skip
    loaded = 0
    for folder in folders:
        for algo in ALGORITHMS:
            file = (folder or ROOT / "baselines" / "hyperparams") / f"{algo}.yml"
            if file.is_file():
                for env_id in load_yaml(read_text(file, "hp"), str(file)):
                    load_hyperparams(algo, env_id, folder)
                    loaded += 1
    assert loaded >= 20


def test_shipped_models_and_statistics_load() -> None:
    pytest.importorskip("stable_baselines3")
    import gymnasium as gym

    from baselines.models.model_files import load_sb3_model
    from baselines.models.normalization import load_statistics, statistics_path

    manifest = load_json(read_bounded(SHIPPED / "manifest.json", "manifest"), "manifest")
    assert {e["file"] for e in manifest} == {p.name for p in SHIPPED.glob("*.zip")}
    for entry in manifest:
        env = gym.make(entry["env_id"])
        try:
            load_sb3_model(SHIPPED / entry["file"], env=env)
            stats = statistics_path(SHIPPED / entry["file"])
            if stats is not None:
                load_statistics(stats, env)
        finally:
            env.close()


def test_the_docs_show_the_table_as_it_is() -> None:
    from sgc_env.scenario.caps import caps_markdown

    assert caps_markdown() in (ROOT / "docs" / "untrusted-files.md").read_text()


def test_a_cap_message_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "huge.json"
    path.write_bytes(b" " * (cap("file_bytes") + 1))
    with pytest.raises(FileLimitError, match=f"result {path}: {cap('file_bytes') + 1} bytes"):
        read_bounded(path, "result")
    with pytest.raises(ScenarioError, match="bodies: 33 bodies; at most 32"):
        _bodies(33, tmp_path)
    assert json.dumps(CAPS)  # plain data: the docs table is written from it
