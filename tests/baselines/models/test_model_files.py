"""Issue 25: model files from elsewhere run no code; malformed ones get a clear error, exit 2.

Each payload below is real: loaded the way SB3 and pickle load by default (``--trust-model``)
it runs a shell command that creates a marker file. The tests show that ``sgc evaluate``,
``sgc rollout`` and ``sgc demo --policy`` never create it without that flag, and either load
the model safely or refuse naming the file. The demo's models are built on the three-rod env's
spaces, so that its safe path really loads them and flies the demo.
"""

from __future__ import annotations

import base64
import io
import json
import os
import pickle
import re
import zipfile
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import sgc_env  # noqa: E402, F401
from baselines.cli import main as cli  # noqa: E402

SHIPPED = Path(__file__).resolve().parents[3] / "baselines" / "checkpoints"


class Payload:
    """Unpickled, runs ``touch MARKER`` (what a hostile file would do, harmlessly)."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self) -> tuple:
        return (os.system, (f"touch '{self.marker}'",))


def _clean_model(path: Path, env_id: str = "SGCPoint-v1") -> Path:
    from stable_baselines3 import PPO

    env = gym.make(env_id)
    PPO("MlpPolicy", env, n_steps=64, batch_size=64, seed=0, device="cpu",
        policy_kwargs={"net_arch": [8]}).save(path)  # fmt: skip
    env.close()
    return path


def _rewrite(source: Path, target: Path, **members: bytes | None) -> Path:
    """A copy of the zip ``source`` with ``members`` replaced (None: left out)."""
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w") as zout:
        for info in zin.infolist():
            if info.filename in members:
                content = members[info.filename]
                if content is not None:
                    zout.writestr(info.filename, content)
            else:
                zout.writestr(info, zin.read(info.filename))
    return target


def _pickled_field_model(clean: Path, target: Path, marker: Path) -> Path:
    """The clean model with the payload in its ``policy_class`` and ``lr_schedule`` pickles."""
    with zipfile.ZipFile(clean) as archive:
        data = json.loads(archive.read("data"))
    blob = base64.b64encode(pickle.dumps(Payload(marker))).decode()
    for key in ("policy_class", "lr_schedule"):
        data[key][":serialized:"] = blob
    return _rewrite(clean, target, data=json.dumps(data).encode())


def _pickled_weights_model(clean: Path, target: Path, marker: Path) -> Path:
    import torch as th

    buffer = io.BytesIO()
    th.save({"weight": Payload(marker)}, buffer)
    return _rewrite(clean, target, **{"policy.pth": buffer.getvalue()})


def _evaluate(policy: Path, tmp: Path, *extra: str) -> int:
    return cli.main(["evaluate", "--policy", str(policy), "--env", "SGCPoint-v1", "--episodes",
                     "1", "--no-plots", "--out", str(tmp / "ev"), *extra])  # fmt: skip


def _rollout(policy: Path, tmp: Path, *extra: str) -> int:
    return cli.main(["rollout", "--policy", str(policy), "--env", "SGCPoint-v1", "--no-compare",
                     "--out", str(tmp / "ro"), *extra])  # fmt: skip


def _demo(policy: Path, tmp: Path, *extra: str) -> int:
    return cli.main(["demo", "--policy", str(policy), "--no-video", "--out", str(tmp / "demo"),
                     *extra])  # fmt: skip


COMMANDS = {"evaluate": _evaluate, "rollout": _rollout, "demo": _demo}


@pytest.fixture(scope="module")
def clean_models(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A clean model per env the commands run on: the point for evaluate and rollout, the
    three rods for the demo."""
    folder = tmp_path_factory.mktemp("clean")
    return {"SGCPoint-v1": _clean_model(folder / "model.zip"),
            "SGCThreeRods-v2": _clean_model(folder / "rods.zip", "SGCThreeRods-v2")}  # fmt: skip


@pytest.fixture(scope="module")
def clean(clean_models: dict[str, Path]) -> Path:
    return clean_models["SGCPoint-v1"]


def _clean_for(command: str, clean_models: dict[str, Path]) -> Path:
    return clean_models["SGCThreeRods-v2" if command == "demo" else "SGCPoint-v1"]


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_pickled_field_in_the_zip_runs_nothing_and_the_model_loads_safely(
    command: str, clean_models: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    clean = _clean_for(command, clean_models)
    marker = tmp_path / "pwned"
    evil = _pickled_field_model(clean, tmp_path / "evil.zip", marker)
    assert COMMANDS[command](evil, tmp_path) == 0  # rebuilt from the JSON, nothing unpickled
    assert not marker.exists()
    capsys.readouterr()
    assert COMMANDS[command](evil, tmp_path, "--trust-model") in (0, 2)  # the payload is real
    assert marker.exists()
    assert "can run any code" in capsys.readouterr().err


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_pickled_statistics_beside_a_clean_model_are_refused(
    command: str, clean_models: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    clean = _clean_for(command, clean_models)
    marker = tmp_path / "pwned"
    model = tmp_path / "m.zip"
    model.write_bytes(clean.read_bytes())
    stats = tmp_path / "m.vecnormalize.pkl"
    stats.write_bytes(pickle.dumps(Payload(marker)))
    assert COMMANDS[command](model, tmp_path) == 2
    err = capsys.readouterr().err
    assert str(stats) in err and "pickle" in err and "Traceback" not in err
    assert not marker.exists()
    COMMANDS[command](model, tmp_path, "--trust-model")  # fails after unpickling: not a venv
    assert marker.exists()


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_pickled_weights_are_refused_by_weights_only(
    command: str, clean_models: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    clean = _clean_for(command, clean_models)
    marker = tmp_path / "pwned"
    evil = _pickled_weights_model(clean, tmp_path / "evil.zip", marker)
    assert COMMANDS[command](evil, tmp_path) == 2
    err = capsys.readouterr().err
    assert str(evil) in err and "weights_only" in err
    assert not marker.exists()


def _truncated(clean: Path, tmp: Path) -> Path:
    blob = clean.read_bytes()
    (tmp / "bad.zip").write_bytes(blob[: len(blob) // 2])
    return tmp / "bad.zip"


def _no_data(clean: Path, tmp: Path) -> Path:
    return _rewrite(clean, tmp / "bad.zip", data=None)


def _no_weights(clean: Path, tmp: Path) -> Path:
    return _rewrite(clean, tmp / "bad.zip", **{"policy.pth": None})


def _not_json(clean: Path, tmp: Path) -> Path:
    return _rewrite(clean, tmp / "bad.zip", data=b"{not json")


def _foreign_class(clean: Path, tmp: Path) -> Path:
    with zipfile.ZipFile(clean) as archive:
        data = json.loads(archive.read("data"))
    data["policy_kwargs"] = {":type:": "<class 'dict'>", ":serialized:": "",
                             "activation_fn": "<class 'subprocess.Popen'>"}  # fmt: skip
    return _rewrite(clean, tmp / "bad.zip", data=json.dumps(data).encode())


def _shadowing_field(clean: Path, tmp: Path) -> Path:
    with zipfile.ZipFile(clean) as archive:
        data = json.loads(archive.read("data"))
    data["predict"] = "not a method"
    return _rewrite(clean, tmp / "bad.zip", data=json.dumps(data).encode())


def _other_env(clean: Path, tmp: Path) -> Path:
    return _clean_model(tmp / "rod.zip", "SGCRod-v1")  # trained on the rod: 6 actions, not 3


def _wrong_statistics(clean: Path, tmp: Path) -> Path:
    model = tmp / "m.zip"
    model.write_bytes(clean.read_bytes())
    stats = {"format": "sgc-vecnormalize-1", "norm_obs": True, "norm_reward": False,
             "clip_obs": 10.0, "clip_reward": 10.0, "gamma": 0.99, "epsilon": 1e-8,
             "obs_rms": {"shape": [4], "mean": [0.0] * 4, "var": [1.0] * 4, "count": 1.0},
             "ret_rms": {"shape": [], "mean": [0.0], "var": [1.0], "count": 1.0}}  # fmt: skip
    (tmp / "m.vecnormalize.json").write_text(json.dumps(stats))
    return model


MALFORMED = {
    "truncated": (_truncated, "truncated or corrupt"),
    "no data": (_no_data, "missing member(s) ['data']"),
    "no weights": (_no_weights, "missing member(s) ['policy.pth']"),
    "data not json": (_not_json, "member 'data': not valid JSON"),
    "class off the allow-list": (_foreign_class, "'subprocess.Popen', which is not on the"),
    "field shadowing a method": (_shadowing_field, "would replace PPO.predict"),
    "other env's spaces": (_other_env, "action space Box(shape=(6,), float32) does not fit"),
    "statistics of another shape": (_wrong_statistics, "do not fit the env's observations"),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_model_files_exit_2_naming_file_and_problem(
    case: str, clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    build, problem = MALFORMED[case]
    model = build(clean, tmp_path)
    assert _evaluate(model, tmp_path) == 2
    err = capsys.readouterr().err
    assert err.startswith("sgc evaluate: error:") and err.count("\n") == 1, err
    assert problem in err and model.stem in err


def test_shipped_model_on_the_wrong_env_names_the_env_it_was_trained_on(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    argv = ["evaluate", "--policy", "shipped:SGCPoint-v1", "--env", "SGCRod-v1", "--episodes",
            "1", "--no-plots", "--out", str(tmp_path)]  # fmt: skip
    assert cli.main(argv) == 2
    assert "(trained on SGCPoint-v1)" in capsys.readouterr().err


def test_safe_and_trusted_loading_predict_alike(clean: Path) -> None:
    from baselines.models.model_files import load_sb3_model

    env = gym.make("SGCPoint-v1")
    obs, _ = env.reset(seed=3)
    safe = load_sb3_model(clean, env=env)
    trusted = load_sb3_model(clean, env=env, trust_model=True)
    np.testing.assert_array_equal(safe.predict(obs, deterministic=True)[0],
                                  trusted.predict(obs, deterministic=True)[0])  # fmt: skip
    assert type(safe.policy) is type(trusted.policy)
    with pytest.raises(ValueError, match="pass env"):
        load_sb3_model(clean)
    env.close()


def test_shipped_models_hold_no_pickle_beside_them() -> None:
    assert not list(SHIPPED.glob("*.pkl"))
    assert sorted(p.name for p in SHIPPED.glob("*.vecnormalize.json")) == [
        "ppo_caps_SGCThreeRodsRandom-v3.vecnormalize.json",
    ]


def test_demo_refuses_a_model_of_other_spaces_before_unpickling(
    clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    marker = tmp_path / "pwned"
    evil = _pickled_field_model(clean, tmp_path / "evil.zip", marker)  # the point's 3 actions
    assert _demo(evil, tmp_path) == 2
    err = capsys.readouterr().err
    assert err.startswith("sgc demo: error:") and err.count("\n") == 1, err
    assert "does not fit" in err and "evil" in err
    assert not marker.exists() and not (tmp_path / "demo").exists()


def test_every_class_a_shipped_model_names_is_allowed() -> None:
    from baselines.models.model_files import allowed_classes, read_model_data

    named = set()
    for model in sorted(SHIPPED.glob("*.zip")):
        data, _ = read_model_data(model.read_bytes(), str(model))
        named |= set(re.findall(r"<class '(baselines\.[\w.]+)'>", json.dumps(data)))
    assert named and all(name in allowed_classes() for name in named), named


def test_a_model_of_sgc_before_1_0_is_refused_in_one_line_saying_so(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """Files saved before 1.0 name the model classes by their old modules: one line says what
    the file is and what to do (nothing is unpickled)."""
    shipped = SHIPPED / "ppo_caps_SGCThreeRodsRandom-v3.zip"
    with zipfile.ZipFile(shipped) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    members["data"] = members["data"].replace(b"baselines.models.", b"baselines.agents.")
    old = tmp_path / "old.zip"
    with zipfile.ZipFile(old, "w") as archive:
        for name, blob in members.items():
            archive.writestr(name, blob)
    argv = ["evaluate", "--policy", str(old), "--env", "SGCThreeRodsRandom-v3", "--episodes",
            "1", "--no-plots", "--out", str(tmp_path / "ev")]  # fmt: skip
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "old.zip" in err, err
    assert "baselines.agents.per_body.PerBodyPolicy' of sgc before 1.0" in err
    assert "Migrating to 1.0" in err
