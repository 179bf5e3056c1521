"""``sgc`` argument checks (exit 2, one line, no traceback, before any work) and outputs that
are moved into place only when a run finishes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from baselines.cli import main as cli
from baselines.cli.checks import staged_output


@pytest.fixture
def a_file(tmp_path) -> Path:
    path = tmp_path / "a_file"
    path.write_text("not a folder")
    return path


DEMOS = ["demos", "--env", "SGCPoint-v1", "--episodes", "1"]
TRAIN = ["train", "--algo", "ppo", "--env", "SGCPoint-v1"]

# (argv with {file} for a plain file and {tmp} for a folder, fragment of the one-line error)
BAD = [
    (["evaluate", "--seed", "-1"], "argument --seed: expected an integer >= 0, got -1"),
    (["evaluate", "--out", "{file}"], "exists and is not a folder"),
    (["evaluate", "--out", "{file}/sub"], "is a file, so"),
    (["evaluate", "--out", "/proc/no_such/x"], "cannot write in /proc"),
    (["evaluate", "--episodes", "0"], "argument --episodes: expected an integer >= 1"),
    (["evaluate", "--episodes", "two"], "expected an integer, got 'two'"),
    (["evaluate", "--tolerance-position", "nan"], "expected a finite number"),
    (["evaluate", "--env", "Nope-v0", "--out", "{tmp}"], "--env: unknown environment 'Nope-v0'"),
    (["rollout", "--seed", "-5"], "argument --seed"),
    (["rollout", "--out", "{file}"], "exists and is not a folder"),
    ([*DEMOS, "--out", "{tmp}"], "is a folder; give a file name"),
    ([*DEMOS, "--out", "{file}/x.npz"], "is a file, so"),
    ([*DEMOS, "--seed", "-1", "--out", "{tmp}/d.npz"], "argument --seed"),
    ([*DEMOS, "--out", "{tmp}/d.npz", "--env-kwargs", "[1"], "not valid JSON"),
    ([*DEMOS, "--out", "{tmp}/d.npz", "--env-kwargs", "[1]"], "expected a JSON object"),
    ([*DEMOS, "--out", "{tmp}/d.npz", "--push-prob", "2"], "expected a number in [0, 1]"),
    ([*DEMOS, "--out", "{tmp}/d.npz", "--push-scale", "-1"], "expected a number >= 0"),
    (["demos", "--env", "Nope-v0", "--episodes", "1", "--out", "{tmp}/d.npz"], "--env:"),
    ([*TRAIN, "--seed", "-1"], "argument --seed"),
    ([*TRAIN, "--timesteps", "-1"], "argument --timesteps"),
    ([*TRAIN, "--out", "{file}"], "exists and is not a folder"),
    ([*TRAIN, "--demos", "{tmp}/none.npz"], "no such file"),
    ([*TRAIN, "--hyperparams", "{tmp}/none"], "no such folder"),
    ([*TRAIN, "--init", "bc"], "--init bc needs --demos"),
    (["train", "--algo", "ppo", "--env", "Nope-v0"], "--env:"),
    (["demo", "--width", "0"], "argument --width: expected an integer in [16, 4096]"),
    (["demo", "--height", "99999"], "argument --height"),
    (["demo", "--out", "{file}"], "exists and is not a folder"),
]


@pytest.mark.parametrize(("argv", "fragment"), BAD, ids=[" ".join(b[0]) for b in BAD])
def test_bad_argument_exits_2_with_one_line(argv, fragment, tmp_path, a_file, capsys):
    argv = [a.format(file=a_file, tmp=tmp_path) for a in argv]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"sgc {argv[0]}: error: ") and fragment in last, err
    assert list(tmp_path.iterdir()) == [a_file]  # nothing was written


def test_staged_output_commits_on_success_and_keeps_other_files(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("other")
    (out / "a.txt").write_text("old")
    with staged_output(out) as stage:
        (stage / "a.txt").write_text("new")
        (stage / "sub").mkdir()
        (stage / "sub" / "b.txt").write_text("new")
        assert not (out / "sub").exists()  # nothing appears before the end
    assert (out / "a.txt").read_text() == "new" and (out / "sub" / "b.txt").read_text() == "new"
    assert (out / "keep.txt").read_text() == "other"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # the stage is gone


def test_interrupted_staged_output_leaves_the_old_results(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "video.mp4").write_bytes(b"the earlier, whole video")
    with pytest.raises(KeyboardInterrupt), staged_output(out) as stage:
        (stage / "video.mp4").write_bytes(b"48 bytes")
        raise KeyboardInterrupt
    assert (out / "video.mp4").read_bytes() == b"the earlier, whole video"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_interrupted_evaluate_keeps_the_earlier_results(tmp_path, monkeypatch, capsys):
    from baselines.cli.commands import evaluate as command

    out = tmp_path / "ev"
    argv = ["evaluate", "--env", "SGCPoint-v1", "--episodes", "1", "--no-plots", "--out", str(out)]
    assert cli.main([*argv, "--seed", "1"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    write = command._write_pair

    def write_then_interrupt(result, folder, plots):
        write(result, folder, plots)
        raise KeyboardInterrupt

    monkeypatch.setattr(command, "_write_pair", write_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        cli.main([*argv, "--seed", "2"])
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert json.loads(before["summary.json"])["n_goals"] > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ev"]


def test_interrupted_demo_leaves_no_stub_video_beside_old_plates(tmp_path, monkeypatch):
    import baselines.figures.demo_compare as demo_module

    out = tmp_path / "demo"
    out.mkdir()
    (out / "plates.png").write_bytes(b"earlier plates")
    (out / "three_rods.mp4").write_bytes(b"earlier, whole video")

    def interrupted(options, progress):
        (options.out / "three_rods.mp4").write_bytes(b"48-byte stub")
        raise KeyboardInterrupt

    monkeypatch.setattr(demo_module, "run_demo", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cli.main(["demo", "--out", str(out), "--width", "96", "--height", "64"])
    assert (out / "three_rods.mp4").read_bytes() == b"earlier, whole video"
    assert (out / "plates.png").read_bytes() == b"earlier plates"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo"]


def test_interrupted_train_keeps_the_earlier_run_and_the_new_checkpoints(tmp_path, monkeypatch):
    import baselines.agents.train as train_module

    out = tmp_path / "run"
    out.mkdir()
    (out / "final_model.zip").write_bytes(b"the earlier, whole model")
    (out / "config.json").write_text('{"earlier": true}')

    def interrupted(cfg, hp=None):
        (Path(cfg.out) / "checkpoints").mkdir()
        (Path(cfg.out) / "checkpoints" / "ppo_64_steps.zip").write_bytes(b"checkpoint")
        (Path(cfg.out) / "final_model.zip").write_bytes(b"half a model")
        raise KeyboardInterrupt

    monkeypatch.setattr(train_module, "train", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cli.main([*TRAIN, "--out", str(out)])
    assert (out / "final_model.zip").read_bytes() == b"the earlier, whole model"
    assert json.loads((out / "config.json").read_text()) == {"earlier": True}
    assert (out / "checkpoints" / "ppo_64_steps.zip").read_bytes() == b"checkpoint"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_interrupted_demos_save_keeps_the_earlier_file(tmp_path, monkeypatch):
    import baselines.common.atomic_files as atomic

    out = tmp_path / "d.npz"
    out.write_bytes(b"the earlier, whole demos")

    def interrupted(fd):
        raise KeyboardInterrupt

    monkeypatch.setattr(atomic.os, "fsync", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cli.main([*DEMOS, "--out", str(out)])
    assert out.read_bytes() == b"the earlier, whole demos"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.npz"]
    monkeypatch.undo()
    assert cli.main([*DEMOS, "--out", str(out)]) == 0
    assert out.read_bytes()[:2] == b"PK" and sorted(p.name for p in tmp_path.iterdir()) == ["d.npz"]
