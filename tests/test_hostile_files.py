"""Crafted hostile files of every kind, through the ``sgc`` command that reads them.

Each case builds its file(s) under a fresh folder and runs one command in-process. Every case
must: run no code (a payload would create ``pwned``), write nothing outside ``--out`` (the
whole folder is listed before and after), finish within 10 s with under 1 GB traced by
``tracemalloc`` (numpy's arrays included), and end either in exit 2 with one stderr line
``sgc CMD: error: ...`` that names the file (no raw newline, no terminal escape) or in a
correct run (exit 0).
"""

from __future__ import annotations

import io
import json
import os
import pickle
import struct
import time
import tracemalloc
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from baselines.cli import main as cli  # noqa: E402

SHIPPED = Path(__file__).resolve().parents[1] / "baselines" / "checkpoints"
GIB = 1 << 30
POINT = "SGCPoint-v1"
ANSI = "\x1b[32m\nsgc evaluate: ok\x1b[0m"


class Payload:
    """Unpickled, creates the marker file (what a hostile file would do, harmlessly)."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self) -> tuple:
        return (os.system, (f"touch '{self.marker}'",))


@dataclass(frozen=True)
class Case:
    """``build(tmp, clean_model) -> (argv, named)``: ``named`` is what the error line must
    contain (the file), None for a run that must succeed; ``fragment`` is also required."""

    build: Callable[[Path, Path], tuple[list[str], str | None]]
    fragment: str = ""


# ---------------------------------------------------------------- scenarios (sgc rollout)


def _rollout(file: Path, tmp: Path) -> list[str]:
    return ["rollout", "--scenario", str(file), "--no-compare", "--out", str(tmp / "out")]


def _scenario_text(text: str) -> Callable[[Path, Path], tuple[list[str], str | None]]:
    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        file = tmp / "hostile.yaml"
        file.write_text(text.replace("PWNED", str(tmp / "pwned")), encoding="utf-8")
        return _rollout(file, tmp), str(file)

    return build


BODY = "{name: b, shape: sphere, size: [0.05], position: [0, 0, 1], goals: [GOALS]}"
GOAL = "{nail: [0, 0.1, 1], time: 0.3}"


def _with_goals(goals: str) -> str:
    return "name: h\nbodies: [" + BODY.replace("GOALS", goals) + "]\n"


def _alias_bomb(top: str) -> str:
    lines = ["a0: &a0 [" + ", ".join(["1"] * 10) + "]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 9)]
    return "\n".join(lines) + f"\n{top}: *a8\n"


def _non_utf8(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    file = tmp / "latin.yaml"
    file.write_bytes(_with_goals(GOAL).encode() + b"# caf\xe9\n")
    return _rollout(file, tmp), str(file)


def _oversized(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    file = tmp / "big.yaml"
    file.write_text(_with_goals(GOAL) + "#" + "x" * (9 << 20) + "\n")
    return _rollout(file, tmp), str(file)


def _named_elsewhere(name: str) -> Callable[[Path, Path], tuple[list[str], str | None]]:
    """A valid scenario whose ``name`` points outside; no --out (the default folder)."""

    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        file = tmp / "scene.yaml"
        file.write_text(f"name: {json.dumps(name.replace('TMP', str(tmp)))}\n"
                        + _with_goals(GOAL).split("\n", 1)[1])  # fmt: skip
        return ["rollout", "--scenario", str(file), "--no-compare"], None

    return build


def _links_in_out(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    """--out holds links to a file and a folder elsewhere, named like the outputs."""
    victim = tmp / "victim.txt"
    victim.write_text("precious\n")
    out = tmp / "out"
    out.mkdir()
    (out / "summary.json").symlink_to(victim)
    (out / "deviation.png").symlink_to(tmp / "dangling")
    return ["rollout", "--env", "SGCPoint-v1", "--no-compare", "--out", str(out)], None


SCENARIOS: dict[str, Case] = {
    "yaml nested 100k deep": Case(_scenario_text("bodies: " + "[" * 100_000), "nest"),
    "yaml alias bomb": Case(_scenario_text(_alias_bomb("bodies")), "values; at most"),
    "3000 bodies": Case(_scenario_text(
        "bodies: [" + ", ".join([BODY.replace("GOALS", GOAL)] * 3000) + "]\n"),
        "bodies: 3000 bodies; at most"),
    "40 KB of path goals": Case(_scenario_text(_with_goals(", ".join(
        ["{path: {curve: line, start: [0, 0, 1], end: [1, 0, 1]}, samples: 1000}"] * 400))),
        "goals; at most"),
    "200k polyline waypoints": Case(_scenario_text(_with_goals(
        "{path: {curve: polyline, waypoints: [" + ", ".join(["[0, 0, 1]"] * 200_000)
        + "]}, samples: 10, time: 5}")), "bytes; at most"),
    "2000 polyline waypoints": Case(_scenario_text(_with_goals(
        "{path: {curve: polyline, waypoints: [" + ", ".join(["[0, 0, 1]"] * 2000)
        + "]}, samples: 10, time: 5}")), "path.waypoints: 2000 points; at most"),
    "2-D path start": Case(_scenario_text(_with_goals(
        "{path: {curve: line, start: [0, 0], end: [1, 0, 1]}, samples: 3, time: 2}")),
        "path.start: expected 3 numbers"),
    "turns as a string": Case(_scenario_text(_with_goals(
        "{path: {curve: helix, center: [0, 0, 1], radius: 0.1, turns: '1e12', height: 1}, "
        "samples: 3, time: 2}")), "path.turns: expected a number"),
    "python tag": Case(_scenario_text(
        "name: !!python/object/apply:os.system ['touch PWNED']\n" + _with_goals(GOAL)),
        "not valid YAML"),
    "not utf-8": Case(_non_utf8, "not UTF-8"),
    "9 MB file": Case(_oversized, "bytes; at most"),
    "5000-digit mass": Case(_scenario_text(_with_goals(GOAL).replace(
        "size: [0.05]", "size: [0.05], mass: " + "9" * 5000)), "digits"),
    "terminal escapes in a bad field": Case(_scenario_text(
        f"name: {json.dumps(ANSI)}\n" + _with_goals(GOAL).split("\n", 1)[1].replace(
            "position: [0, 0, 1]", f"position: {json.dumps(ANSI)}")), "position"),
    "name ../../victim, no --out": Case(_named_elsewhere("../../victim")),
    "absolute name, no --out": Case(_named_elsewhere("TMP/victim")),
    "links already in --out": Case(_links_in_out),
}  # fmt: skip


# ---------------------------------------------------------------- model zips (sgc evaluate)


def _evaluate(model: Path, tmp: Path, env: str = "SGCPoint-v1") -> list[str]:
    return ["evaluate", "--policy", str(model), "--env", env, "--episodes", "1", "--no-plots",
            "--out", str(tmp / "out")]  # fmt: skip


def _edit_zip(source: Path, target: Path, data: Callable[[dict], Any] | None = None,
              **members: bytes | None) -> Path:  # fmt: skip
    """A copy of ``source`` with ``data`` edited and ``members`` replaced (None: dropped)."""
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w") as zout:
        for info in zin.infolist():
            content = zin.read(info.filename)
            if info.filename == "data" and data is not None:
                edited = data(json.loads(content))
                content = edited if isinstance(edited, bytes) else json.dumps(edited).encode()
            if info.filename in members:
                content = members.pop(info.filename)  # type: ignore[assignment]
                if content is None:
                    continue
            zout.writestr(info.filename, content)
        for name, content in members.items():
            if content is not None:
                zout.writestr(name, content)
    return target


def _model(edit: Callable[[dict], Any] | None = None, env: str = "SGCPoint-v1",
           source: Path | None = None, **members: Any):  # fmt: skip
    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        made = {k: v(tmp) if callable(v) else v for k, v in members.items()}
        model = _edit_zip(source or clean, tmp / "hostile.zip", edit, **made)
        return _evaluate(model, tmp, env), str(model)

    return build


def _set(key: str, value: Any) -> Callable[[dict], dict]:
    def edit(data: dict) -> dict:
        data[key] = value
        return data

    return edit


def _space_dtype(data: dict) -> dict:
    data["action_space"]["dtype"] = "float32" + ANSI
    return data


def _net_arch(data: dict) -> dict:
    data["policy_kwargs"]["net_arch"] = [8000] * 4
    return data


def _dict_space(data: dict) -> dict:
    data["observation_space"] = {":type:": "<class 'gymnasium.spaces.dict.Dict'>",
                                 "spaces": "{'a': Box(" + "0, " * 47_000 + "}"}  # fmt: skip
    return data


def _foreign_gains_env(data: dict) -> dict:
    data["policy_kwargs"]["gains_env"] = "CartPole-v1"
    return data


def _pickled_class(tmp: Path) -> Callable[[dict], dict]:
    import base64

    def edit(data: dict) -> dict:
        data["policy_class"][":serialized:"] = base64.b64encode(
            pickle.dumps(Payload(tmp / "pwned"))).decode()  # fmt: skip
        return data

    return edit


def _torch_variables(key: str) -> Callable[[Path], bytes]:
    def build(tmp: Path) -> bytes:
        import torch as th

        buffer = io.BytesIO()
        th.save({key: th.zeros(1)}, buffer)
        return buffer.getvalue()

    return build


def _claim_size(path: Path, member: str, size: int) -> Path:
    """Rewrite the central directory so that ``member`` claims ``size`` bytes."""
    blob = bytearray(path.read_bytes())
    at = blob.find(b"PK\x01\x02")
    while at >= 0:
        length = struct.unpack_from("<H", blob, at + 28)[0]
        if blob[at + 46 : at + 46 + length].decode() == member:
            struct.pack_into("<I", blob, at + 24, size)
        at = blob.find(b"PK\x01\x02", at + 4)
    path.write_bytes(bytes(blob))
    return path


def _huge_member(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    model = _claim_size(_edit_zip(clean, tmp / "hostile.zip"), "system_info.txt", 0xF000_0000)
    return _evaluate(model, tmp), str(model)


def _beside(name: str, content: str, env: str = "SGCRod-v1"):
    """The clean (point) model on another env, with ``name`` written beside it."""

    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        model = tmp / "m.zip"
        model.write_bytes(clean.read_bytes())
        (tmp / name).write_text(content)
        return _evaluate(model, tmp, env), str(model if name == "config.json" else tmp / name)

    return build


STATS = {"format": "sgc-vecnormalize-1", "norm_obs": True, "norm_reward": False,
         "clip_obs": 10.0, "clip_reward": 10.0, "gamma": 0.99, "epsilon": 1e-8,
         "ret_rms": {"shape": [], "mean": [0.0], "var": [1.0], "count": 1.0}}  # fmt: skip


def _stats(obs_var: str = "1.0", **settings: Any) -> str:
    rms = (f'{{"shape": [50], "mean": [{", ".join(["0.0"] * 50)}], '
           f'"var": [{obs_var}{", 1.0" * 49}], "count": 1.0}}')  # fmt: skip
    text = json.dumps({**STATS, **settings, "obs_rms": "RMS"})
    return text.replace('"RMS"', rms)


MODELS: dict[str, Case] = {
    "data nested 100k deep": Case(_model(lambda d: b"[" * 100_000 + b"]" * 100_000),
                                  "nested too deeply"),
    "data 5000-digit integer": Case(_model(lambda d: b'{"n": ' + b"9" * 5000 + b"}"),
                                    "not valid JSON"),
    "net_arch [8000]*4": Case(_model(_net_arch), "net_arch[0]: 8000 units; at most 4096"),
    "140 KB Dict space text": Case(_model(_dict_space, env="SGCPointGoal-v1")),
    "8 GiB member claimed": Case(_huge_member, "'system_info.txt': 4026531840 bytes; at most"),
    "100 members": Case(_model(**{f"x{i}.txt": b"x" for i in range(100)}), "members; at most"),
    "pytorch_variables __class__": Case(_model(**{"pytorch_variables.pth":
                                                  _torch_variables("__class__")}), "__class__"),
    "pytorch_variables attribute path": Case(_model(**{
        "pytorch_variables.pth": _torch_variables("policy.action_net.weight")}),
        "'policy.action_net.weight' is not one of"),
    "foreign .pth member": Case(_model(**{"__class__.pth": _torch_variables("x")}),
                                "not weights SB3 writes"),
    "gains_env of a foreign env": Case(_model(
        _foreign_gains_env, env="SGCThreeRodsRandom-v3",
        source=SHIPPED / "ppo_caps_SGCThreeRodsRandom-v3.zip"), "gains_env must be an SGC"),
    "escapes in a space dtype": Case(_model(_space_dtype), "does not fit"),
    "escapes in config.json env_id": Case(_beside("config.json", json.dumps({"env_id": ANSI})),
                                          "trained on"),
    "config.json nested 100k deep": Case(_beside("config.json", "[" * 100_000), "does not fit"),
    "statistics var Infinity": Case(_beside("m.vecnormalize.json", _stats("Infinity"), POINT),
                                    "finite"),
    "statistics clip_obs -1": Case(_beside("m.vecnormalize.json", _stats(clip_obs=-1.0), POINT),
                                   "clip_obs must be in"),
    "statistics nested 100k deep": Case(_beside("m.vecnormalize.json", "[" * 100_000, POINT),
                                        "nested too deeply"),
}  # fmt: skip


def _payload_runs_nothing(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    model = _edit_zip(clean, tmp / "evil.zip", _pickled_class(tmp))
    return _evaluate(model, tmp), None


MODELS["pickled policy_class loads safely"] = Case(_payload_runs_nothing)


# ---------------------------------------------------------------- recipes and hyperparameters


def _recipes(content: bytes) -> Callable[[Path, Path], tuple[list[str], str | None]]:
    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        file = tmp / "recipes.yml"
        file.write_bytes(content)
        return ["benchmark", "--recipes", str(file), "--env", "SGCPoint-v1", "--seeds", "1",
                "--out", str(tmp / "out"), "--no-plots", "--report-only"], str(file)  # fmt: skip

    return build


def _hyperparams(lines: str, *extra: str) -> Callable[[Path, Path], tuple[list[str], str | None]]:
    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        folder = tmp / "hp"
        folder.mkdir()
        (folder / "ppo.yml").write_text("SGCPoint-v1:\n  n_timesteps: 64\n  policy: MlpPolicy\n"
                                        + lines)  # fmt: skip
        return ["train", "--algo", "ppo", "--env", "SGCPoint-v1", "--timesteps", "64",
                "--hyperparams", str(folder), "--out", str(tmp / "out"), *extra], \
            str(folder / "ppo.yml")  # fmt: skip

    return build


def _env_kwargs_flag(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    return ["train", "--algo", "ppo", "--env", "SGCPoint-v1", "--timesteps", "64",
            "--env-kwargs", '{"sim_frequency": 10000000}', "--out", str(tmp / "out")], \
        "env_kwargs: sim_frequency"  # fmt: skip


RECIPES: dict[str, Case] = {
    "recipes not utf-8": Case(_recipes(b"recipes:\n  - {algo: ppo}  # caf\xe9\n"), "not UTF-8"),
    "recipes alias bomb": Case(_recipes(_alias_bomb("recipes").encode()), "values; at most"),
    "recipe sim_frequency 1e7": Case(_recipes(
        b"recipes:\n  - {algo: ppo, env_kwargs: {sim_frequency: 10000000}}\n"), "sim_frequency"),
    "hyperparams refused policy_kwargs": Case(_hyperparams(
        "  policy_kwargs: 'dict(activation_fn=os.system)'\n"), "'os.system' is not allowed"),
    "hyperparams net_arch [8000]*4": Case(_hyperparams(
        "  policy_kwargs: 'dict(net_arch=[8000, 8000, 8000, 8000])'\n"), "8000 units"),
    "hyperparams n_envs 100000": Case(_hyperparams("  n_envs: 100000\n"), "n_envs: 100000"),
    "hyperparams nested 100k deep": Case(_hyperparams("  gamma: " + "[" * 100_000 + "\n"),
                                         "nest"),
    "--env-kwargs sim_frequency 1e7": Case(_env_kwargs_flag, "sim_frequency must be"),
}  # fmt: skip


# ---------------------------------------------------------------- benchmark results


def _results(name: str, content: str) -> Callable[[Path, Path], tuple[list[str], str | None]]:
    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        folder = tmp / "out" / "runs" / "SGCPoint-v1" / "ppo" / "seed0"
        folder.mkdir(parents=True)
        (folder / name).write_text(content)
        return ["benchmark", "--algo", "ppo", "--env", "SGCPoint-v1", "--seeds", "1",
                "--out", str(tmp / "out"), "--report-only", "--no-plots"], str(folder / name)

    return build


SPEC = {"env_id": "SGCPoint-v1", "seed": 0, "eval_episodes": 50, "test_seed": 20000,
        "recipe": {"name": "ppo", "algo": "ppo", "demonstrations": False}}  # fmt: skip


def _out_is_a_file(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
    (tmp / "out").write_text("not a folder")
    return ["benchmark", "--algo", "ppo", "--env", "SGCPoint-v1", "--out", str(tmp / "out"),
            "--report-only"], str(tmp / "out")  # fmt: skip


RESULTS: dict[str, Case] = {
    "result.json malformed": Case(_results("result.json", '{"spec": '), "not valid JSON"),
    "result.json a list": Case(_results("result.json", "[1, 2]"), "expected a JSON object"),
    "result.json keys missing": Case(_results("result.json", json.dumps({"spec": SPEC})),
                                     "timesteps must be a finite number"),
    "result.json of another run": Case(_results("result.json", json.dumps({"spec": {}})),
                                       "is not the run"),
    "failed.json a list": Case(_results("failed.json", "[]"), "expected a JSON object"),
    "result.json nested 100k deep": Case(_results("result.json", "[" * 100_000),
                                         "nested too deeply"),
    "--out is a file": Case(_out_is_a_file, "exists and is not a folder"),
}  # fmt: skip


# ---------------------------------------------------------------- demonstrations (train --init bc)


def _npz(tmp: Path, replace: dict[str, bytes] | None = None, **arrays: Any) -> Path:
    rows = 4
    obs = np.zeros((rows, 50), np.float32)
    content = dict(observations=obs, actions=np.zeros((rows, 3), np.float32),
                   rewards=np.zeros(rows, np.float32), terminations=np.zeros(rows, bool),
                   truncations=np.zeros(rows, bool), episode_starts=np.ones(rows, bool),
                   seeds=np.arange(1), env_id=np.array("SGCPoint-v1"),
                   env_kwargs=np.array("{}"), pushes=np.array("{}"),
                   format_version=np.array(1))  # fmt: skip
    content.update(arrays)
    path = tmp / "demos.npz"
    np.savez(path, **content)
    if replace:
        path = _edit_zip(path, tmp / "edited.npz", **replace)
    return path


def _demos(make: Callable[[Path], Path]) -> Callable[[Path, Path], tuple[list[str], str | None]]:
    def build(tmp: Path, clean: Path) -> tuple[list[str], str | None]:
        file = make(tmp)
        return ["train", "--algo", "ppo", "--env", "SGCPoint-v1", "--timesteps", "64", "--init",
                "bc", "--demos", str(file), "--out", str(tmp / "out")], str(file)  # fmt: skip

    return build


def _claimed_rows(tmp: Path) -> Path:
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f4", "fortran_order": False, "shape": (10**12, 50)})
    return _npz(tmp, {"observations.npy": header.getvalue() + bytes(64)})


def _bomb(tmp: Path) -> Path:
    return _claim_size(_npz(tmp), "observations.npy", 0xF000_0000)


def _object_array(tmp: Path) -> Path:
    return _npz(tmp, observations=np.array([Payload(tmp / "pwned")], dtype=object))


DEMOS: dict[str, Case] = {
    "npz claiming 10^12 rows": Case(_demos(_claimed_rows), "bytes; at most"),
    "npz member claiming 3.75 GiB": Case(_demos(_bomb), "(declared size"),
    "npz object array payload": Case(_demos(_object_array), "holds Python objects"),
    "npz env_kwargs sim_frequency 1e7": Case(_demos(lambda tmp: _npz(
        tmp, env_kwargs=np.array('{"sim_frequency": 10000000}'))), "sim_frequency must be"),
    "npz env_kwargs an unknown kwarg": Case(_demos(lambda tmp: _npz(
        tmp, env_kwargs=np.array('{"no_such_kwarg": 1}'))), "does not take"),
    "npz env_kwargs nested 100k deep": Case(_demos(lambda tmp: _npz(
        tmp, env_kwargs=np.array("[" * 100_000))), "nested too deeply"),
    "npz foreign env id": Case(_demos(lambda tmp: _npz(tmp, env_id=np.array("CartPole-v1"))),
                               "recorded on"),
}  # fmt: skip

CASES = {**{f"scenario: {k}": v for k, v in SCENARIOS.items()},
         **{f"model: {k}": v for k, v in MODELS.items()},
         **{f"recipes: {k}": v for k, v in RECIPES.items()},
         **{f"results: {k}": v for k, v in RESULTS.items()},
         **{f"demos: {k}": v for k, v in DEMOS.items()}}  # fmt: skip


# ---------------------------------------------------------------- the runner


@pytest.fixture(scope="module")
def clean(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import gymnasium as gym
    from stable_baselines3 import PPO

    import baselines.evaluation.harness  # noqa: F401
    import baselines.figures.plots  # noqa: F401  (imports are not the file's work: done first)
    import sgc_env  # noqa: F401

    env = gym.make("SGCPoint-v1")
    path = tmp_path_factory.mktemp("clean") / "model.zip"
    PPO("MlpPolicy", env, n_steps=64, batch_size=64, seed=0, device="cpu",
        policy_kwargs={"net_arch": [8]}).save(path)  # fmt: skip
    env.close()
    return path


def _tree(root: Path) -> dict[Path, tuple[float, int]]:
    """Every path under ``root``: a file's (or link's) time and size, a folder's existence."""
    return {p: (0.0, 0) if p.is_dir() and not p.is_symlink() else
            (p.lstat().st_mtime, p.lstat().st_size) for p in root.rglob("*")}  # fmt: skip


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_file(name: str, clean: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                      capsys: pytest.CaptureFixture) -> None:  # fmt: skip
    from stable_baselines3 import PPO

    case = CASES[name]
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    argv, named = case.build(tmp_path, clean)
    before = _tree(tmp_path)
    capsys.readouterr()
    tracemalloc.start()
    started = time.perf_counter()
    try:
        code = cli.main(argv)
    finally:
        seconds = time.perf_counter() - started
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert seconds < 10.0 and peak < GIB, (seconds, peak)
    assert not (tmp_path / "pwned").exists() and not hasattr(PPO, "data")
    outs = (tmp_path / "out", work / "runs")
    changed = [p for p, stamp in _tree(tmp_path).items() if before.get(p) != stamp]
    assert [p for p in changed if not any(p.is_relative_to(o) for o in outs)] == [], changed
    if named is None:
        assert code == 0, err
        assert not (tmp_path / "victim").exists() and not (work / "victim").exists()
        if (tmp_path / "victim.txt").exists():
            assert (tmp_path / "victim.txt").read_text() == "precious\n"
            assert not (tmp_path / "out" / "summary.json").is_symlink()
        return
    lines = [line for line in err.splitlines() if not line.startswith(("usage:", " "))]
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith(f"sgc {argv[0]}: error:"), err
    assert "\x1b" not in err and "Traceback" not in err
    assert named in lines[0] and case.fragment in lines[0], lines[0]


def test_the_suite_covers_every_kind() -> None:
    kinds = {name.split(":")[0] for name in CASES}
    assert kinds == {"scenario", "model", "recipes", "results", "demos"}
    assert len(CASES) >= 50
