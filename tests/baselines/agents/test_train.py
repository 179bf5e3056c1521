"""Learned agents: hyperparameter loading, SB3 smoke runs, demos, cloning, reproducibility."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from baselines.agents.hyperparams import load_hyperparams, parse_kwargs_string  # noqa: E402
from baselines.agents.train import TrainConfig, train  # noqa: E402

TINY = {
    "ppo.yml": """
SGCPoint-v1:
  n_timesteps: 256
  policy: MlpPolicy
  n_envs: 2
  n_steps: 64
  batch_size: 64
  n_epochs: 2
  policy_kwargs: "dict(net_arch=[16], activation_fn=nn.Tanh)"
""",
    "sac.yml": """
SGCPoint-v1:
  n_timesteps: 200
  policy: MlpPolicy
  learning_starts: 100
  batch_size: 32
  buffer_size: 1000
  policy_kwargs: "dict(net_arch=[16])"
""",
    "td3.yml": """
SGCPoint-v1:
  n_timesteps: 200
  policy: MlpPolicy
  learning_starts: 100
  batch_size: 32
  buffer_size: 1000
  noise_type: normal
  noise_std: 0.1
  learning_rate: lin_1e-3
  policy_kwargs: "dict(net_arch=[16])"
""",
    "her.yml": """
SGCPointGoal-v1:
  n_timesteps: 200
  policy: MultiInputPolicy
  learning_starts: 160
  batch_size: 32
  buffer_size: 1000
  replay_buffer_class: HerReplayBuffer
  replay_buffer_kwargs: "dict(goal_selection_strategy='future', n_sampled_goal=2)"
  policy_kwargs: "dict(net_arch=[16])"
""",
}


@pytest.fixture()
def tiny_hp(tmp_path: Path) -> Path:
    folder = tmp_path / "hp"
    folder.mkdir()
    for name, text in TINY.items():
        (folder / name).write_text(text)
    return folder


# ---------------------------------------------------------------- hyperparameters


def test_parse_kwargs_string_is_safe() -> None:
    import torch.nn as nn

    parsed = parse_kwargs_string("dict(net_arch=dict(pi=[64, 64], vf=[32]), activation_fn=nn.ReLU)")
    assert parsed == {"net_arch": {"pi": [64, 64], "vf": [32]}, "activation_fn": nn.ReLU}
    assert parse_kwargs_string("{'log_std_init': -1.5}") == {"log_std_init": -1.5}
    for bad in ("__import__('os').system('true')", "dict(a=open('x'))", "[1, 2]", "dict("):
        with pytest.raises(ValueError, match="policy_kwargs"):
            parse_kwargs_string(bad)


def test_shipped_hyperparams_load_for_every_algo() -> None:
    for algo, env_id in (("ppo", "SGCPoint-v1"), ("sac", "SGCRod-v1"), ("td3", "SGCPoint-v1"),
                         ("her", "SGCPointGoal-v1")):  # fmt: skip
        hp = load_hyperparams(algo, env_id)
        assert hp.n_timesteps > 0 and hp.policy
        assert "net_arch" in hp.algo_kwargs["policy_kwargs"]


def test_hyperparams_errors_name_the_field(tmp_path: Path, tiny_hp: Path) -> None:
    with pytest.raises(ValueError, match="algo"):
        load_hyperparams("dqn", "SGCPoint-v1", tiny_hp)
    with pytest.raises(ValueError, match="SGCRod-v1"):
        load_hyperparams("ppo", "SGCRod-v1", tiny_hp)
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "ppo.yml").write_text("SGCPoint-v1: {policy: MlpPolicy\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        load_hyperparams("ppo", "SGCPoint-v1", tmp_path / "bad")
    (tmp_path / "bad" / "ppo.yml").write_text("SGCPoint-v1: {policy: MlpPolicy}\n")
    with pytest.raises(ValueError, match="n_timesteps"):
        load_hyperparams("ppo", "SGCPoint-v1", tmp_path / "bad")
    (tmp_path / "bad" / "ppo.yml").write_text(
        "SGCPoint-v1: {policy: MlpPolicy, n_timesteps: 10, n_stepz: 5}\n"
    )
    with pytest.raises(ValueError, match="n_stepz"):
        load_hyperparams("ppo", "SGCPoint-v1", tmp_path / "bad")


def test_train_rejects_bad_arguments(tiny_hp: Path) -> None:
    with pytest.raises(ValueError, match="algo"):
        train(TrainConfig(algo="a3c", env_id="SGCPoint-v1", hyperparams_dir=tiny_hp))
    with pytest.raises(ValueError, match="env"):
        train(TrainConfig(algo="ppo", env_id="Nope-v0", hyperparams_dir=tiny_hp))
    with pytest.raises(ValueError, match="demos"):
        train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", init="bc", hyperparams_dir=tiny_hp))


# ---------------------------------------------------------------- smoke runs


@pytest.mark.parametrize(
    ("algo", "env_id"),
    [("ppo", "SGCPoint-v1"), ("sac", "SGCPoint-v1"), ("td3", "SGCPoint-v1"),
     ("her", "SGCPointGoal-v1")],
)  # fmt: skip
def test_smoke_train_save_load_evaluate(
    algo: str, env_id: str, tiny_hp: Path, tmp_path: Path
) -> None:
    from baselines.evaluation.harness import evaluate

    out = tmp_path / algo
    result = train(
        TrainConfig(
            algo=algo, env_id=env_id, seed=3, out=out, eval_freq=150, eval_episodes=1,
            checkpoint_freq=100, hyperparams_dir=tiny_hp, command="test",
        )
    )  # fmt: skip
    assert result.timesteps >= 200
    for name in ("final_model.zip", "best_model.zip", "config.json", "evaluations.json"):
        assert (out / name).is_file(), name
    assert list((out / "checkpoints").glob("*.zip"))
    assert list((out / "tb").rglob("events.out.tfevents*"))
    config = json.loads((out / "config.json").read_text())
    assert config["algo"] == algo and config["seed"] == 3 and config["command"] == "test"
    assert result.evaluations and "success_rate" in result.evaluations[-1]
    if algo == "her":
        import gymnasium as gym

        from baselines.agents.train import load_model

        policy = load_model(out / "final_model.zip", env=gym.make(env_id))
    else:
        policy = str(out / "final_model.zip")
    scored = evaluate(policy, env_id, 1, 10_000)
    assert scored.summary["n_goals"] >= 1
    assert 0.0 <= scored.summary["success_rate"] <= 1.0


def _ppo_params(model) -> np.ndarray:
    return np.concatenate([p.detach().numpy().ravel() for p in model.policy.parameters()])


def test_same_seed_same_parameters_and_scorecard(tiny_hp: Path) -> None:
    runs = [
        train(
            TrainConfig(
                algo="ppo",
                env_id="SGCPoint-v1",
                seed=7,
                eval_freq=256,
                eval_episodes=1,
                hyperparams_dir=tiny_hp,
            )
        )  # fmt: skip
        for _ in range(2)
    ]
    np.testing.assert_array_equal(_ppo_params(runs[0].model), _ppo_params(runs[1].model))
    keys = ("success_rate", "position_error_mean", "position_error_max", "return_mean")
    first, second = runs[0].evaluations[-1], runs[1].evaluations[-1]
    assert {k: first[k] for k in keys} == {k: second[k] for k in keys}
    other = train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", seed=8, timesteps=128,
                              hyperparams_dir=tiny_hp))  # fmt: skip
    assert not np.array_equal(_ppo_params(runs[0].model), _ppo_params(other.model))


# ---------------------------------------------------------------- demos and cloning


def test_demos_roundtrip_and_cli(tmp_path: Path) -> None:
    from baselines.agents.demos import load_demos, record_demos
    from baselines.cli.commands import demos as demos_command

    demos = record_demos("SGCPoint-v1", 2, seed=5)
    assert demos.n_episodes == 2 and list(demos.seeds) == [5, 6]
    import gymnasium as gym

    env = gym.make("SGCPoint-v1")
    obs_shape = env.observation_space.shape
    env.close()
    assert demos.observations.shape == (len(demos), *obs_shape)
    assert demos.actions.shape == (len(demos), 3)
    assert np.all(np.abs(demos.actions) <= 1.0)
    assert demos.truncations[-1] or demos.terminations[-1]
    path = tmp_path / "d.npz"
    parser = argparse.ArgumentParser()
    demos_command.add_arguments(parser)
    args = parser.parse_args(
        ["--env", "SGCPoint-v1", "--episodes", "2", "--seed", "5", "--out", str(path)]
    )
    assert demos_command.run(args) == 0
    loaded = load_demos(path)
    np.testing.assert_array_equal(loaded.actions, demos.actions)
    np.testing.assert_array_equal(loaded.observations, demos.observations)
    assert loaded.env_id == "SGCPoint-v1" and loaded.env_kwargs == {}
    with pytest.raises(ValueError, match="env"):
        record_demos("SGCPointGoal-v1", 1, seed=0)
    with pytest.raises(ValueError, match="demos"):
        load_demos(tmp_path / "missing.npz")


PUSHES = {"scale": 0.5, "spin": 0.5, "prob": 0.1, "start": True}


def test_pushes_are_seeded_and_recorded(tmp_path: Path) -> None:
    from baselines.agents.demos import load_demos, record_demos
    from baselines.agents.pushes import Pushes
    from baselines.cli.commands import demos as demos_command

    plain = record_demos("SGCThreeRods-v2", 2, seed=0)
    pushed = record_demos("SGCThreeRods-v2", 2, seed=0, pushes=Pushes(**PUSHES))
    again = record_demos("SGCThreeRods-v2", 2, seed=0, pushes=Pushes(**PUSHES))
    np.testing.assert_array_equal(pushed.observations, again.observations)
    np.testing.assert_array_equal(pushed.actions, again.actions)
    first, second = (obs for obs in np.split(plain.observations, 2))
    np.testing.assert_array_equal(first, second)  # a fixed scene: every episode the same
    starts = np.flatnonzero(pushed.episode_starts)
    assert not np.array_equal(pushed.observations[starts[0]], plain.observations[0])
    assert not np.array_equal(pushed.observations[starts[0]], pushed.observations[starts[1]])
    never = record_demos("SGCThreeRods-v2", 2, seed=0, pushes=Pushes(scale=0.5, prob=0.0))
    np.testing.assert_array_equal(never.observations, plain.observations)
    path = tmp_path / "pushed.npz"
    parser = argparse.ArgumentParser()
    demos_command.add_arguments(parser)
    args = parser.parse_args(
        ["--env", "SGCThreeRods-v2", "--episodes", "2", "--seed", "0", "--out", str(path),
         "--push-scale", "0.5", "--push-spin", "0.5", "--push-prob", "0.1", "--push-start"]
    )  # fmt: skip
    assert demos_command.run(args) == 0
    loaded = load_demos(path)
    assert loaded.pushes == Pushes(**PUSHES) and plain.pushes == Pushes()
    np.testing.assert_array_equal(loaded.observations, pushed.observations)


def test_default_pushes_draw_nothing() -> None:
    from baselines.agents.pushes import Pushes, apply_random_push, push_rng

    rng = push_rng(3)
    state = rng.bit_generator.state
    obs = np.zeros(4, np.float32)
    assert apply_random_push(None, obs, Pushes(), rng, tick=0) is obs
    assert rng.bit_generator.state == state


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"scale": -0.1}, "push_scale"), ({"spin": float("nan")}, "push_spin"),
     ({"scale": 0.1, "prob": 1.5}, "push_prob"), ({"start": True}, "push_start")],
)  # fmt: skip
def test_bad_push_arguments_raise(kwargs: dict, name: str, tiny_hp: Path) -> None:
    from baselines.agents.pushes import Pushes, push_rng

    with pytest.raises(ValueError, match=name):
        Pushes(**kwargs)
    with pytest.raises(ValueError, match=name):
        train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", hyperparams_dir=tiny_hp,
                          **{f"push_{k}": v for k, v in kwargs.items()}))  # fmt: skip
    with pytest.raises(ValueError, match="seed"):
        push_rng(-1)
    with pytest.raises(ValueError, match="dagger-rounds"):
        train(TrainConfig(algo="ppo", env_id="SGCPoint-v1", hyperparams_dir=tiny_hp,
                          push_scale=0.1))  # fmt: skip


def test_dagger_pushes_diversify_rollouts_of_a_fixed_scene() -> None:
    from baselines.agents.bc import dagger
    from baselines.agents.demos import record_demos
    from baselines.agents.pushes import Pushes
    from baselines.agents.train import algorithm_class

    demos = record_demos("SGCIntercept-v1", 1, seed=0)

    def rollout_states(pushes: Pushes | None) -> np.ndarray:
        model = algorithm_class("ppo")("MlpPolicy", "SGCIntercept-v1", seed=0, device="cpu",
                                       policy_kwargs={"net_arch": [8]})  # fmt: skip
        aggregate, _ = dagger(model, demos, 1, 2, seed=0, epochs=1, pushes=pushes)
        return aggregate.observations[len(demos) :]

    plain = rollout_states(None)
    first, second = np.split(plain, 2)
    np.testing.assert_array_equal(first, second)  # a deterministic clone: one path, twice
    pushed = rollout_states(Pushes(scale=0.5, start=True))
    np.testing.assert_array_equal(pushed, rollout_states(Pushes(scale=0.5, start=True)))
    first, second = np.split(pushed[: 2 * (len(pushed) // 2)], 2)
    assert not np.array_equal(first, second)
    assert not np.array_equal(pushed[0], plain[0])


def test_behaviour_cloning_reduces_imitation_loss(tmp_path: Path, tiny_hp: Path) -> None:
    from baselines.agents.bc import imitation_loss
    from baselines.agents.demos import record_demos

    demos = record_demos("SGCPoint-v1", 3, seed=0)
    path = demos.save(tmp_path / "d.npz")
    result = train(
        TrainConfig(
            algo="ppo",
            env_id="SGCPoint-v1",
            timesteps=0,
            init="bc",
            demos=path,
            bc_epochs=20,
            dagger_rounds=1,
            dagger_episodes=1,
            hyperparams_dir=tiny_hp,
            out=tmp_path / "bc",
        )  # fmt: skip
    )
    assert result.bc["loss_after"] < 0.5 * result.bc["loss_before"]
    assert result.bc["samples_after_dagger"] > len(demos)
    assert imitation_loss(result.model, demos) < result.bc["loss_before"]
    import gymnasium as gym

    from baselines.policies import load_sb3_model

    reloaded = load_sb3_model(tmp_path / "bc" / "final_model.zip", env=gym.make("SGCPoint-v1"))
    obs = demos.observations[:5]
    np.testing.assert_allclose(
        reloaded.predict(obs, deterministic=True)[0],
        result.model.predict(obs, deterministic=True)[0],
        atol=1e-6,
    )


@pytest.mark.parametrize("algo", ["sac", "td3"])
def test_behaviour_cloning_into_off_policy_actor(algo: str, tiny_hp: Path) -> None:
    from baselines.agents.bc import behaviour_clone, imitation_loss
    from baselines.agents.demos import record_demos
    from baselines.agents.train import algorithm_class

    demos = record_demos("SGCPoint-v1", 2, seed=1)
    model = algorithm_class(algo)("MlpPolicy", "SGCPoint-v1", seed=0, device="cpu",
                                  policy_kwargs={"net_arch": [32]})  # fmt: skip
    before = imitation_loss(model, demos)
    behaviour_clone(model, demos, epochs=20, seed=0)
    assert imitation_loss(model, demos) < before
    if algo == "td3":
        for a, b in zip(model.actor.parameters(), model.actor_target.parameters(), strict=True):
            assert np.array_equal(a.detach().numpy(), b.detach().numpy())


def test_train_command_runs(tmp_path: Path, tiny_hp: Path) -> None:
    from baselines.cli.commands import train as train_command

    parser = argparse.ArgumentParser()
    train_command.add_arguments(parser)
    args = parser.parse_args(
        ["--algo", "ppo", "--env", "SGCPoint-v1", "--timesteps", "128", "--out",
         str(tmp_path / "run"), "--hyperparams", str(tiny_hp)]
    )  # fmt: skip
    assert train_command.run(args) == 0
    assert (tmp_path / "run" / "final_model.zip").is_file()
    config = json.loads((tmp_path / "run" / "config.json").read_text())
    assert config["train_config"]["out"] == str(tmp_path / "run")  # not the stage it was in
    assert not list(tmp_path.glob(".run.partial-*"))  # the stage is gone


# ---------------------------------------------------------------- shipped models and long runs

CHECKPOINTS = Path(__file__).resolve().parents[3] / "baselines" / "checkpoints"


def test_shipped_checkpoints_are_small_and_score() -> None:
    from baselines.evaluation.harness import evaluate

    models = sorted(CHECKPOINTS.glob("*.zip"))
    if not models:
        pytest.skip("no shipped checkpoints")
    assert sum(m.stat().st_size for m in models) <= 5 * 1024 * 1024
    point = CHECKPOINTS / "ppo_dagger_SGCPoint-v1.zip"
    assert point.is_file()
    result = evaluate(str(point), "SGCPoint-v1", 10, 10_000)
    assert result.summary["success_rate"] >= 0.9
    assert result.summary["position_error_max"] <= 0.02


#: Shipped model -> (env id, success it must keep on held-out seed 10000), docs/zoo.md.
SHIPPED_SCORES = {
    "ppo_dagger_SGCPoint-v1.zip": ("SGCPoint-v1", 0.9),
    "ppo_caps_SGCThreeRodsRandom-v3.zip": ("SGCThreeRodsRandom-v3", 0.85),
}


def test_every_shipped_checkpoint_is_listed() -> None:
    assert sorted(m.name for m in CHECKPOINTS.glob("*.zip")) == sorted(SHIPPED_SCORES)


@pytest.mark.parametrize("name", sorted(SHIPPED_SCORES))
def test_shipped_checkpoint_scores_through_sgc_evaluate(name: str, tmp_path: Path) -> None:
    from baselines.cli import main as cli

    env_id, success = SHIPPED_SCORES[name]
    out = tmp_path / "ev"
    argv = ["evaluate", "--policy", str(CHECKPOINTS / name), "--env", env_id, "--episodes", "1",
            "--seed", "10000", "--no-plots", "--out", str(out)]  # fmt: skip
    assert cli.main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_goals"] > 0 and summary["success_rate"] >= success


@pytest.mark.slow
def test_dagger_reaches_ninety_percent_on_point(tmp_path: Path) -> None:
    """The shipped recipe, end to end (about two minutes on one CPU core)."""
    from baselines.agents.demos import record_demos

    path = record_demos("SGCPoint-v1", 200, seed=0).save(tmp_path / "demos.npz")
    result = train(
        TrainConfig(
            algo="ppo",
            env_id="SGCPoint-v1",
            seed=0,
            timesteps=0,
            init="bc",
            demos=path,
            bc_epochs=60,
            dagger_rounds=6,
            dagger_episodes=30,
            eval_freq=1,
            eval_episodes=20,
        )  # fmt: skip
    )
    assert result.evaluations[-1]["success_rate"] >= 0.9


def test_critic_warmup_keeps_the_actor_still() -> None:
    from baselines.agents.bc import actor_parameters
    from baselines.agents.callbacks import FreezeActorCallback
    from baselines.agents.train import algorithm_class

    def snapshot(params) -> np.ndarray:
        return np.concatenate([p.detach().numpy().ravel().copy() for p in params])

    def fresh():
        return algorithm_class("ppo")(
            "MlpPolicy", "SGCPoint-v1", seed=1, device="cpu", n_steps=64, batch_size=64,
            n_epochs=2, policy_kwargs={"net_arch": [16]},
        )  # fmt: skip

    model = fresh()
    actor, critic = snapshot(actor_parameters(model)), snapshot(model.policy.value_net.parameters())
    model.learn(128, callback=FreezeActorCallback(10_000))
    assert np.array_equal(snapshot(actor_parameters(model)), actor)
    assert not np.array_equal(snapshot(model.policy.value_net.parameters()), critic)
    model = fresh()
    model.learn(192, callback=FreezeActorCallback(64))
    assert not np.array_equal(snapshot(actor_parameters(model)), actor)


def test_normalize_saves_statistics_and_evaluates_on_raw_observations(tmp_path: Path) -> None:
    folder = tmp_path / "hp"
    folder.mkdir()
    (folder / "ppo.yml").write_text(
        "SGCPoint-v1: {n_timesteps: 128, policy: MlpPolicy, n_steps: 64, batch_size: 64,\n"
        "  n_epochs: 1, normalize: true, policy_kwargs: 'dict(net_arch=[8])'}\n"
    )
    out = tmp_path / "run"
    result = train(
        TrainConfig(
            algo="ppo",
            env_id="SGCPoint-v1",
            eval_freq=128,
            eval_episodes=1,
            hyperparams_dir=folder,
            out=out,
        )  # fmt: skip
    )
    assert (out / "vecnormalize.json").is_file() and (out / "best_model.zip").is_file()
    assert result.evaluations and result.evaluations[-1]["n_goals"] >= 1
