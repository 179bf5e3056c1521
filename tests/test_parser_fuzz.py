"""Hypothesis against every parser of files from elsewhere: whatever the bytes, a parser
returns its value or raises ``ValueError`` (its own subclass, naming the file); never another
exception, and never slower than the deadline. The scenario parser's own fuzzing is
tests/test_scenario_fuzz.py; here are the path curves, JSON and YAML readers, rl-zoo3 kwargs
strings, hyperparameter and recipe files, VecNormalize statistics, model zips, demonstration
npz files and benchmark results. Few examples each, derandomized, so the module stays fast.
"""

from __future__ import annotations

import io
import json
import zipfile
from datetime import timedelta
from pathlib import Path
from typing import Any

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from sgc_env.scenario import ScenarioError, scenario_from_dict  # noqa: E402
from sgc_env.scenario.bounded import FileLimitError, load_json, load_yaml  # noqa: E402

FUZZ = settings(max_examples=40, deadline=timedelta(seconds=5), derandomize=True,
                suppress_health_check=[HealthCheck.too_slow,
                                       HealthCheck.function_scoped_fixture])  # fmt: skip

JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner,
                                                                max_size=4),  # fmt: skip
    max_leaves=12,
)
TOKENS = ["[", "]", "{", "}", ",", ":", '"', "'", "&a", "*a", "!!python/name:os.system", "-",
          "1e400", "9" * 5000, "NaN", "Infinity", "\x00", "\x1b[31m", "\n", "\t",
          "null"]  # fmt: skip
TEXT = st.lists(st.sampled_from(TOKENS) | st.text(max_size=5), max_size=30).map("".join)


@pytest.fixture(scope="module", autouse=True)
def _imported() -> None:
    """The parsers' modules imported once, outside the deadline of the first draw."""
    import importlib.util

    if importlib.util.find_spec("stable_baselines3") is None:
        return
    for module in ("baselines.agents.hyperparams", "baselines.benchmark.grid",
                   "baselines.benchmark.results", "baselines.models.normalization",
                   "baselines.models.model_files", "baselines.agents.demos"):  # fmt: skip
        importlib.import_module(module)


def _mutate(blob: bytes, edits: list[tuple[int, int]]) -> bytes:
    data = bytearray(blob)
    for at, value in edits:
        if data:
            data[at % len(data)] = value
    return bytes(data)


EDITS = st.lists(st.tuples(st.integers(0, 1 << 20), st.integers(0, 255)), min_size=1,
                 max_size=6)  # fmt: skip


@FUZZ
@given(reader=st.sampled_from([load_json, load_yaml]), text=TEXT)
def test_json_and_yaml_readers(reader: Any, text: str) -> None:
    try:
        reader(text, "fuzz")
    except FileLimitError as exc:
        assert str(exc).startswith("fuzz: ")


CURVES = st.fixed_dictionaries({"curve": st.sampled_from(["line", "arc", "helix", "polyline", 5])},
                               optional={k: JSON | st.lists(st.floats(), max_size=4)
                                         for k in ("start", "end", "center", "radius", "turns",
                                                   "height", "start_angle", "end_angle",
                                                   "waypoints")})  # fmt: skip


@FUZZ
@given(CURVES, JSON)
def test_path_goal_parameters(path: dict[str, Any], samples: Any) -> None:
    body = {"name": "b", "goals": [{"path": path, "samples": samples, "time": 2.0}]}
    try:
        scenario_from_dict({"bodies": [body]})
    except ScenarioError as exc:
        assert str(exc).startswith(("bodies[0]", "goals")), exc


@FUZZ
@given(TEXT)
def test_policy_kwargs_strings(text: str) -> None:
    pytest.importorskip("stable_baselines3")
    from baselines.agents.hyperparams import parse_kwargs_string

    try:
        assert isinstance(parse_kwargs_string(text), dict)
    except ValueError as exc:
        assert str(exc).startswith("policy_kwargs: ")


def _hyperparams(folder: Path) -> Any:
    from baselines.agents.hyperparams import load_hyperparams

    return load_hyperparams("ppo", "SGCPoint-v1", folder)


def _recipes(folder: Path) -> Any:
    from baselines.benchmark.grid import load_recipes

    return load_recipes(folder / "ppo.yml")


#: An rl-zoo3 YAML reader -> the file it reads (``ppo.yml`` in a folder) as a valid text.
YAML_FILES = {
    _hyperparams: "SGCPoint-v1:\n  n_timesteps: 64\n  policy: MlpPolicy\n  n_envs: 2\n",
    _recipes: "recipes:\n  - {name: a, algo: ppo, timesteps: 64}\n",
}


@FUZZ
@given(reader=st.sampled_from(list(YAML_FILES)), at=st.integers(0, 60), insert=TEXT)
def test_hyperparameter_and_recipe_files(reader: Any, at: int, insert: str,
                                         tmp_path: Path) -> None:  # fmt: skip
    pytest.importorskip("stable_baselines3")
    text = YAML_FILES[reader]
    (tmp_path / "ppo.yml").write_text(text[:at] + insert + text[at:])
    try:
        reader(tmp_path)
    except ValueError as exc:
        assert "\n" not in str(exc) and "ppo.yml" in str(exc), exc


@pytest.fixture(scope="module")
def point_env() -> Any:
    gym = pytest.importorskip("gymnasium")
    pytest.importorskip("stable_baselines3")
    import sgc_env  # noqa: F401

    env = gym.make("SGCPoint-v1")
    yield env
    env.close()


STATS = {"format": "sgc-vecnormalize-1", "norm_obs": False, "norm_reward": True,
         "clip_obs": 10.0, "clip_reward": 10.0, "gamma": 0.99, "epsilon": 1e-8,
         "obs_rms": None,
         "ret_rms": {"shape": [], "mean": [0.0], "var": [1.0], "count": 1.0}}  # fmt: skip


@FUZZ
@given(key=st.sampled_from(sorted(STATS)), value=JSON)
def test_vecnormalize_statistics(key: str, value: Any, point_env: Any, tmp_path: Path) -> None:
    from baselines.models.normalization import load_statistics

    path = tmp_path / "m.vecnormalize.json"
    path.write_text(json.dumps({**STATS, key: value}))
    try:
        load_statistics(path, point_env)
    except ValueError as exc:
        assert str(path) in str(exc)


@pytest.fixture(scope="module")
def clean_zip(point_env: Any, tmp_path_factory: pytest.TempPathFactory) -> bytes:
    from stable_baselines3 import PPO

    path = tmp_path_factory.mktemp("fuzz") / "m.zip"
    PPO("MlpPolicy", point_env, n_steps=64, batch_size=64, device="cpu",
        policy_kwargs={"net_arch": [8]}).save(path)  # fmt: skip
    return path.read_bytes()


@FUZZ
@given(edits=EDITS)
def test_model_zip_bytes(edits: list[tuple[int, int]], clean_zip: bytes) -> None:
    from baselines.models.model_files import ModelFileError, read_model_data

    try:
        read_model_data(_mutate(clean_zip, edits), "fuzz.zip")
    except ModelFileError as exc:
        assert str(exc).startswith("model file fuzz.zip: ")


@FUZZ
@given(key=st.sampled_from(["policy_kwargs", "observation_space", "action_space",
                            "lr_schedule", "policy_class", "n_steps", "gamma"]),
       value=JSON)  # fmt: skip
def test_model_data_fields(key: str, value: Any, clean_zip: bytes, point_env: Any,
                           tmp_path: Path) -> None:  # fmt: skip
    from baselines.models.model_files import ModelFileError, load_sb3_model

    path = tmp_path / "m.zip"
    with zipfile.ZipFile(io.BytesIO(clean_zip)) as zin, zipfile.ZipFile(path, "w") as zout:
        for info in zin.infolist():
            content = zin.read(info.filename)
            if info.filename == "data":
                data = json.loads(content)
                data[key] = value
                content = json.dumps(data).encode()
            zout.writestr(info.filename, content)
    try:
        load_sb3_model(path, env=point_env)
    except ModelFileError as exc:
        assert str(path) in str(exc)


@FUZZ
@given(edits=EDITS)
def test_demonstration_npz_bytes(edits: list[tuple[int, int]], tmp_path: Path) -> None:
    np = pytest.importorskip("numpy")
    pytest.importorskip("stable_baselines3")
    from baselines.agents.demos import load_demos

    path = tmp_path / "d.npz"
    rows = np.zeros((3, 78), np.float32)
    buffer = io.BytesIO()
    np.savez(buffer, observations=rows, actions=rows[:, :3], rewards=rows[:, 0],
             terminations=rows[:, 0] > 0, truncations=rows[:, 0] > 0,
             episode_starts=rows[:, 0] == 0, seeds=np.arange(1), env_id=np.array("SGCPoint-v1"),
             env_kwargs=np.array("{}"), pushes=np.array("{}"), format_version=np.array(1))
    path.write_bytes(_mutate(buffer.getvalue(), edits))
    try:
        load_demos(path)
    except ValueError as exc:
        assert str(path) in str(exc)


@FUZZ
@given(record=JSON)
def test_benchmark_results(record: Any, tmp_path: Path) -> None:
    pytest.importorskip("stable_baselines3")
    from baselines.benchmark.grid import Recipe, RunSpec
    from baselines.benchmark.results import read_record

    spec = RunSpec(Recipe("ppo", "ppo"), "SGCPoint-v1", 0, 0, 1, 1)
    path = tmp_path / "result.json"
    if isinstance(record, dict):
        record = {"spec": spec.to_dict(), **record}
    path.write_text(json.dumps(record))
    try:
        read_record(path, spec, finished=True)
    except ValueError as exc:
        assert str(path) in str(exc)
