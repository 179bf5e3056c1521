"""Issue 25: every input from elsewhere (hyperparameter and recipe YAML, ``--env-kwargs``
JSON, policy specs) gets one clear line and exit 2, never a traceback, and no spelling of a
spec, a kwarg or a name reaches a module of its choosing."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from baselines.cli import main as cli  # noqa: E402


def _error(argv: list[str], capsys: pytest.CaptureFixture) -> str:
    """The one line ``sgc`` printed for ``argv``, after checking it exited 2 with just it."""
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"sgc {argv[0]}: error:") and err.count("\n") == 1, err
    return err


BASE = ("SGCPoint-v1:\n  n_timesteps: 64\n  policy: MlpPolicy\n  n_steps: 64\n"
        "  batch_size: 64\n  n_epochs: 1\n")  # fmt: skip

#: hyperparameter file -> fragment of the error (each line replaces or extends BASE)
HYPERPARAMS = {
    "  learning_rate: [1, 2]\n": "learning_rate: expected a finite number > 0 or lin_<number>",
    "  gamma: high\n": "gamma must be a finite number, got 'high'",
    "  batch_size: true\n": "batch_size must be an integer, got True",
    "  n_epochs: '2'\n": "n_epochs must be an integer, got '2'",
    "  n_timesteps: 1e400\n": "must be finite numbers",
    "  policy_kwargs: 'dict(activation_fn=os.system)'\n": "name 'os.system' is not allowed",
    "  policy_kwargs: \"__import__('os').system('x')\"\n": "unsupported expression",
    "  policy_kwargs: {net_arch: x}\n": "policy_kwargs.net_arch: expected a list of layer",
    "  normalize: 'dict(clip_obs=\"x\")'\n": "normalize: clip_obs must be a finite number",
    "  normalize: {norm_obs: 1}\n": "normalize: norm_obs must be true/false",
    "  normalize: 'dict(gamma=1.5)'\n": "normalize: gamma must be in (0, 1], got 1.5",
    "  normalize: 'dict(clip_reward=-1.0)'\n": "normalize: clip_reward must be > 0",
    "  policy: [MlpPolicy]\n": "policy must be a name",
}


@pytest.mark.parametrize("line", sorted(HYPERPARAMS))
def test_bad_hyperparameters_exit_2_naming_the_field(
    line: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    key = line.split(":")[0]
    body = "".join(row for row in BASE.splitlines(keepends=True) if row.split(":")[0] != key)
    (tmp_path / "ppo.yml").write_text(body + line)
    argv = ["train", "--algo", "ppo", "--env", "SGCPoint-v1", "--timesteps", "64",
            "--hyperparams", str(tmp_path)]  # fmt: skip
    assert HYPERPARAMS[line] in _error(argv, capsys)


ENV_KWARGS = {
    '{"foo": 1}': "does not take {'foo': 1}: SGCEnv.__init__() got an unexpected keyword",
    '{"reward": 5}': "reward: unknown mode 5",
    '{"scenario": [1]}': "does not take {'scenario': [1]}",
    '{"render_mode": "x"}': "render_mode must be",
}


@pytest.mark.parametrize("kwargs", sorted(ENV_KWARGS))
@pytest.mark.parametrize("command", ["demos", "train"])
def test_bad_env_kwargs_exit_2_before_any_work(
    kwargs: str, command: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    argv = {"demos": ["demos", "--episodes", "1", "--out", str(tmp_path / "d.npz")],
            "train": ["train", "--algo", "ppo", "--timesteps", "64"]}[command]  # fmt: skip
    err = _error([*argv, "--env", "SGCPoint-v1", "--env-kwargs", kwargs], capsys)
    assert ENV_KWARGS[kwargs] in err
    assert list(tmp_path.iterdir()) == []


RECIPES = {
    "{algo: ppo, hyperparams: [1]}": "hyperparams must be a folder name",
    "{algo: ppo, timesteps: true}": "timesteps must be an integer >= 0, got True",
    "{algo: ppo, train: {bc_epochs: x}}": "train option bc_epochs must be an integer",
    "{algo: ppo, train: {init: bc, demos: 5}}": "train option demos must be a string",
    "{algo: ppo, train: {demos: '{env_id.__class__}'}}": "the only placeholders are",
    "{algo: ppo, env_kwargs: {foo: 1}}": "env_kwargs: SGCPoint-v1 does not take {'foo': 1}",
    "{algo: [ppo]}": "algo must be one of",
    "[1, 2]": "expected a mapping, got list",
    "{algo: ppo}\n\t- tab": "not valid YAML: while scanning",
}


@pytest.mark.parametrize("entry", sorted(RECIPES))
def test_bad_recipes_exit_2_naming_the_recipe(
    entry: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    recipes = tmp_path / "r.yml"
    recipes.write_text(f"recipes:\n  - {entry}\n")
    argv = ["benchmark", "--recipes", str(recipes), "--env", "SGCPoint-v1", "--seeds", "1",
            "--out", str(tmp_path / "out"), "--no-plots"]  # fmt: skip
    assert RECIPES[entry] in _error(argv, capsys) and not (tmp_path / "out").exists()


SPECS = {
    "os:system": "unknown spec 'os:system'",
    "shipped:../../etc/passwd": "no shipped model",
    "{tmp}/notes.zip": "not a readable zip archive",
    "{tmp}": "is a folder",
    "subprocess.Popen": "unknown spec",
}


@pytest.mark.parametrize("spec", sorted(SPECS))
@pytest.mark.parametrize("command", ["evaluate", "rollout"])
def test_bad_policy_specs_exit_2(
    spec: str, command: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    (tmp_path / "notes.zip").write_text("a text file named like a model")
    argv = [command, "--policy", spec.format(tmp=tmp_path), "--out", str(tmp_path / "o")]
    if command == "evaluate":
        argv += ["--episodes", "1"]
    assert SPECS[spec] in _error(argv, capsys)


def test_demonstrations_with_a_pickled_array_are_refused(tmp_path: Path) -> None:
    import numpy as np

    from baselines.agents.demos import load_demos

    marker = tmp_path / "pwned"
    path = tmp_path / "d.npz"
    np.savez(path, observations=np.array([_Payload(marker)], dtype=object), format_version=1)
    with pytest.raises(ValueError, match="holds Python objects"):
        load_demos(path)
    assert not marker.exists()
    path.write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(ValueError, match=f"demos: {path}: not a readable npz"):
        load_demos(path)


class _Payload:
    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self) -> tuple:
        import os

        return (os.system, (f"touch '{self.marker}'",))
