"""Train SB3 agents (PPO, SAC, TD3, SAC+HER) on the registered ids, reproducibly.

Everything that decides a run is written next to its model in ``config.json`` (resolved
hyperparameters, seed, command), and every random source is seeded from ``seed``: SB3's
``set_random_seed``, the training envs (``seed + rank``), the model and the evaluation seeds
(held out: :data:`~sgc_env.defaults.EVAL_SEED` onwards). On CPU the same seed and
command give the same parameters and the same scorecard.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.agents.hyperparams import (
    ALGORITHMS,
    Hyperparams,
    algorithm_class,
    training_class,
)
from baselines.agents.pushes import Pushes
from baselines.common.env_kwargs import check_env_kwargs
from sgc_env.defaults import EVAL_SEED

__all__ = [
    "ALGORITHMS",
    "TrainConfig",
    "TrainResult",
    "algorithm_class",
    "load_model",
    "record_run_folder",
    "train",
]


@dataclass
class TrainConfig:
    """One training run; ``timesteps`` overrides the YAML's ``n_timesteps`` when set."""

    algo: str
    env_id: str
    seed: int = 0
    timesteps: int | None = None
    out: str | Path | None = None
    progress: bool = False
    eval_freq: int = 0
    eval_episodes: int = 10
    eval_seed: int = EVAL_SEED
    init: str = "none"
    demos: str | Path | None = None
    bc_epochs: int = 30
    bc_log_std: float = -2.0
    critic_warmup: int = 0
    dagger_rounds: int = 0
    dagger_episodes: int = 20
    push_scale: float = 0.0
    push_spin: float = 0.0
    push_prob: float = 0.05
    push_start: bool = False
    hyperparams_dir: str | Path | None = None
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    device: str = "cpu"
    checkpoint_freq: int = 0
    verbose: int = 0
    command: str = ""
    vec: str | None = None  # batched | dummy | subproc; None: batched where the id has it
    time_budget_s: float | None = None  # stop training after this many seconds (budget.py)
    eval_every_s: float | None = None  # curve points every this many seconds of training


@dataclass
class TrainResult:
    """The trained model and what the run produced."""

    model: Any
    timesteps: int
    wall_time_s: float
    learn_time_s: float  # inside model.learn, less the harness evaluations
    steps_per_s: float
    config: dict[str, Any]
    model_path: Path | None = None
    evaluations: list[dict[str, Any]] = field(default_factory=list)
    bc: dict[str, Any] | None = None


def _make_env(env_id: str, n_envs: int, seed: int, env_kwargs: dict[str, Any], vec: str | None):
    from baselines.agents.sb3_vec_env import make_sgc_vec

    return make_sgc_vec(env_id, n_envs, seed, env_kwargs, vec)


def _action_noise(hp, action_space: gym.spaces.Box):
    from stable_baselines3.common.noise import NormalActionNoise

    if hp.noise_type != "normal":
        return None
    n = action_space.shape[0]
    return NormalActionNoise(np.zeros(n), hp.noise_std * np.ones(n))


def _validate(cfg: TrainConfig) -> None:
    from baselines.agents.budget import check_time_budget

    algorithm_class(cfg.algo)
    check_env_kwargs(cfg.env_id, cfg.env_kwargs, "env_kwargs")
    if cfg.init not in ("none", "bc"):
        raise ValueError(f"init: expected 'none' or 'bc', got {cfg.init!r}")
    if cfg.init == "bc":
        if cfg.demos is None:
            raise ValueError("demos: --init bc needs --demos FILE (see `sgc demos`)")
        if cfg.algo == "her":
            raise ValueError("init: behaviour cloning needs a flat observation; not for her")
    check_time_budget(cfg.time_budget_s)
    check_time_budget(cfg.eval_every_s, "eval_every_s")
    if cfg.eval_freq and cfg.eval_every_s is not None:
        raise ValueError("eval_freq and eval_every_s: curve points by steps or by seconds, "
                         "not both")  # fmt: skip
    if cfg.timesteps is not None and cfg.timesteps < 0:
        raise ValueError(f"timesteps must be >= 0, got {cfg.timesteps}")
    if cfg.eval_freq < 0 or cfg.checkpoint_freq < 0 or cfg.critic_warmup < 0:
        raise ValueError("eval_freq, checkpoint_freq and critic_warmup must be >= 0")
    if _pushes(cfg).active and not (cfg.init == "bc" and cfg.dagger_rounds > 0):
        raise ValueError("push_scale/push_spin act on DAgger rollouts: need --init bc and "
                         "--dagger-rounds >= 1")  # fmt: skip


def _pushes(cfg: TrainConfig) -> Pushes:
    """The DAgger rollouts' pushes (validated by :class:`Pushes`)."""
    return Pushes(cfg.push_scale, cfg.push_spin, cfg.push_prob, cfg.push_start)


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    if isinstance(value, Path):
        return str(value)
    return getattr(value, "__name__", repr(value))


def train(cfg: TrainConfig, hp: Hyperparams | None = None) -> TrainResult:
    """Build, optionally clone from demos, train and save one model (see :class:`TrainConfig`).

    ``hp``: the hyperparameters of ``cfg`` when the caller has parsed them already (they are
    parsed once per run); None reads them from ``cfg.hyperparams_dir``."""
    import torch as th
    from stable_baselines3.common.callbacks import BaseCallback, CallbackList
    from stable_baselines3.common.utils import set_random_seed
    from stable_baselines3.common.vec_env import VecNormalize

    from baselines.agents.budget import TimeBudgetCallback, steps_learned
    from baselines.agents.callbacks import (
        FreezeActorCallback,
        HarnessEvalCallback,
        StatisticsCheckpointCallback,
    )
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.models.normalization import save_statistics

    _validate(cfg)
    started = time.perf_counter()
    th.set_num_threads(1)
    if hp is None:
        hp = load_hyperparams(cfg.algo, cfg.env_id, cfg.hyperparams_dir)
    total = hp.n_timesteps if cfg.timesteps is None else int(cfg.timesteps)
    set_random_seed(cfg.seed)
    env = _make_env(cfg.env_id, hp.n_envs, cfg.seed, cfg.env_kwargs, cfg.vec)
    if hp.normalize:
        # rl-zoo3's rule: the reward's running return uses the algorithm's gamma unless the
        # file's normalize gives its own
        settings = {"gamma": hp.algo_kwargs.get("gamma", 0.99), **hp.normalize_kwargs}
        env = VecNormalize(env, **settings)
    kwargs = dict(hp.algo_kwargs)
    if cfg.init == "bc":
        from baselines.models.features import StandardizeObservation

        policy_kwargs = dict(kwargs.get("policy_kwargs") or {})
        policy_kwargs.setdefault("features_extractor_class", StandardizeObservation)
        kwargs["policy_kwargs"] = policy_kwargs
    noise = _action_noise(hp, env.action_space)
    if noise is not None:
        kwargs["action_noise"] = noise
    out = Path(cfg.out) if cfg.out else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        kwargs["tensorboard_log"] = str(out / "tb")
    try:
        model = training_class(hp)(
            hp.policy, env, seed=cfg.seed, device=cfg.device, verbose=cfg.verbose, **kwargs
        )
    except (TypeError, ValueError, AssertionError) as exc:  # values SB3 itself refuses
        raise ValueError(f"hyperparameters of {cfg.algo} for {cfg.env_id}: {exc}") from None
    bc_info = None
    train_started = time.perf_counter()  # the budget's clock: cloning counts as training
    cpu_started = time.process_time()  # this process only: SubprocVecEnv workers not counted
    if cfg.init == "bc":
        deadline = None if cfg.time_budget_s is None else train_started + cfg.time_budget_s
        bc_info = _clone(model, cfg, deadline)
    callbacks: list[BaseCallback] = []
    if cfg.critic_warmup:
        callbacks.append(FreezeActorCallback(cfg.critic_warmup))
    if out is not None and cfg.checkpoint_freq:
        callbacks.append(
            StatisticsCheckpointCallback(
                max(cfg.checkpoint_freq // hp.n_envs, 1), str(out / "checkpoints"),
                name_prefix=cfg.algo, save_vecnormalize=hp.normalize,
            )
        )  # fmt: skip
    eval_cb = None
    if cfg.eval_freq or cfg.eval_every_s is not None:
        eval_cb = HarnessEvalCallback(
            cfg.env_id, cfg.eval_freq, cfg.eval_episodes, seed=cfg.eval_seed,
            env_kwargs=cfg.env_kwargs, best_model_dir=out,
            vec_normalize=env if hp.normalize else None, verbose=cfg.verbose,
            every_s=cfg.eval_every_s, started=train_started,
        )  # fmt: skip
        callbacks.append(eval_cb)
    budget_cb = None
    if cfg.time_budget_s is not None:
        budget_cb = TimeBudgetCallback(
            cfg.time_budget_s, started=train_started, excluded=(eval_cb,) if eval_cb else ()
        )
        callbacks.append(budget_cb)
    learn_started = time.perf_counter()
    spent_by_cloning = budget_cb is not None and budget_cb.spent()
    if total > 0 and not spent_by_cloning:
        model.learn(
            total, callback=CallbackList(callbacks), progress_bar=cfg.progress,
            tb_log_name=f"{cfg.algo}_{cfg.env_id}_seed{cfg.seed}",
        )  # fmt: skip
    learn_time = time.perf_counter() - learn_started
    train_time = time.perf_counter() - train_started
    train_cpu = time.process_time() - cpu_started
    if eval_cb is not None:
        learn_time -= eval_cb.eval_time_s
        train_time -= eval_cb.eval_time_s
        train_cpu -= eval_cb.eval_cpu_s
    steps = int(model.num_timesteps)
    config = {
        "algo": cfg.algo,
        "algo_class": type(model).__name__,
        "env_id": cfg.env_id,
        "seed": cfg.seed,
        "timesteps": total,
        "steps_reached": steps,
        "steps_learned": steps_learned(model, budget_cb is not None and budget_cb.spent_out),
        "time_budget_s": cfg.time_budget_s,
        "budget_spent": budget_cb is not None and budget_cb.spent_out,
        "hyperparams": _jsonable(hp.raw),
        "train_config": _jsonable(asdict(cfg)),
        "command": cfg.command,
        "bc": bc_info,
    }
    result = TrainResult(
        model=model, timesteps=steps, wall_time_s=0.0, learn_time_s=learn_time,
        steps_per_s=steps / learn_time if learn_time > 0 and steps else 0.0,
        config=config, bc=bc_info,
    )  # fmt: skip
    if eval_cb is not None:
        if total == 0:
            from stable_baselines3.common.logger import Logger

            model.set_logger(Logger(None, []))
            eval_cb.init_callback(model)
        if not eval_cb.history or eval_cb.history[-1]["timesteps"] != steps:
            eval_cb.evaluate_now()
        result.evaluations = eval_cb.history
    result.wall_time_s = time.perf_counter() - started
    config.update(
        wall_time_s=result.wall_time_s, learn_time_s=learn_time, train_time_s=train_time,
        train_cpu_s=train_cpu,
        steps_per_s=result.steps_per_s, evaluations=result.evaluations,
    )  # fmt: skip
    if out is not None:
        result.model_path = Path(model.save(out / "final_model") or out / "final_model.zip")
        if hp.normalize:
            save_statistics(env, out / "vecnormalize.json")
        (out / "config.json").write_text(json.dumps(_jsonable(config), indent=1))
    env.close()
    return result


def record_run_folder(written: Path, out: Path) -> None:
    """Let ``config.json``, written in folder ``written``, name the run folder ``out`` (a
    run staged elsewhere and moved in)."""
    config = written / "config.json"
    data = json.loads(config.read_text())
    data["train_config"]["out"] = str(out)
    config.write_text(json.dumps(data, indent=1))


def _clone(model: Any, cfg: TrainConfig, deadline: float | None = None) -> dict[str, Any]:
    """Behaviour-clone (and optionally DAgger) the new model's actor from ``cfg.demos``;
    no DAgger round starts after ``deadline`` (a ``time.perf_counter()`` reading)."""
    from baselines.agents.bc import behaviour_clone, dagger, imitation_loss
    from baselines.agents.demos import load_demos
    from baselines.models.features import set_statistics

    demos = load_demos(cfg.demos)  # type: ignore[arg-type]
    if demos.env_id != cfg.env_id:
        raise ValueError(f"demos: {cfg.demos}: recorded on {demos.env_id!r}, training on "
                         f"{cfg.env_id!r}")  # fmt: skip
    if demos.observations.shape[1:] != model.observation_space.shape:
        raise ValueError(
            f"demos: {cfg.demos}: observations of shape {demos.observations.shape[1:]} do not fit "
            f"{cfg.env_id}'s {model.observation_space.shape}; re-record them with `sgc demos`"
        )
    set_statistics(model.policy, demos.observations)
    before = imitation_loss(model, demos)
    fit = behaviour_clone(model, demos, epochs=cfg.bc_epochs, seed=cfg.seed, log_std=cfg.bc_log_std)
    info: dict[str, Any] = {
        "demos": str(cfg.demos), "samples": len(demos), "episodes": demos.n_episodes,
        "loss_before": before, "loss_after": fit.epoch_losses[-1],
    }  # fmt: skip
    if cfg.dagger_rounds:
        aggregate, rounds = dagger(
            model, demos, cfg.dagger_rounds, cfg.dagger_episodes, cfg.seed,
            epochs=max(cfg.bc_epochs // 3, 1), log_std=cfg.bc_log_std, pushes=_pushes(cfg),
            deadline=deadline,
        )  # fmt: skip
        info.update(dagger_rounds=rounds.rounds, samples_after_dagger=len(aggregate))
    info["demo_pushes"] = demos.pushes.to_dict()
    return info


def load_model(
    path: str | Path, env: Any | None = None, device: str = "cpu", trust_model: bool = False
) -> Any:
    """Load an SB3 ``.zip`` whatever algorithm wrote it, without unpickling unless
    ``trust_model`` (:mod:`baselines.models.model_files`; safe loading needs ``env``)."""
    from baselines.models.model_files import load_sb3_model

    return load_sb3_model(path, env=env, device=device, trust_model=trust_model)
