"""``sgc train``: train an SB3 agent on a registered id (see baselines.agents.train)."""

from __future__ import annotations

import argparse
import shlex
import sys
from dataclasses import replace

from baselines.cli.checks import (
    UsageError,
    env_kwargs,
    existing_dir,
    existing_file,
    known_env_id,
    nonneg_int,
    out_dir,
    positive_float,
    positive_int,
    staged_output,
)
from baselines.cli.commands.demos import add_push_arguments, push_options
from sgc_env.defaults import EVAL_SEED

ALGOS = ("ppo", "sac", "td3", "her")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--algo", required=True, choices=ALGOS, help="her = SAC + HerReplayBuffer")
    parser.add_argument("--env", required=True, help="registered id, e.g. SGCPoint-v1")
    parser.add_argument("--seed", type=nonneg_int, default=0, help="training seed")
    parser.add_argument(
        "--timesteps", type=nonneg_int, default=None,
        help="override n_timesteps (rounded up to whole rollouts, with a note; 0 with --init bc "
        "scores the clone without RL)",
    )  # fmt: skip
    parser.add_argument(
        "--time-budget", type=positive_float, default=None, metavar="SECONDS",
        help="stop training after SECONDS of wall clock (cloning included, curve evaluations "
        "not); --timesteps stays the upper bound. The steps reached then depend on the machine",
    )  # fmt: skip
    parser.add_argument(
        "--out", type=out_dir, default=None,
        help="run folder: tb/, checkpoints/, models, config.json",
    )  # fmt: skip
    parser.add_argument("--progress", action="store_true", help="show SB3's progress bar")
    parser.add_argument(
        "--eval-freq", type=nonneg_int, default=0,
        help="env steps between harness evaluations (0: off)",
    )  # fmt: skip
    parser.add_argument(
        "--eval-every-s", type=positive_float, default=None, metavar="SECONDS",
        help="seconds of training between harness evaluations (instead of --eval-freq)",
    )  # fmt: skip
    parser.add_argument(
        "--eval-episodes", type=positive_int, default=10, help="episodes per evaluation"
    )
    parser.add_argument(
        "--eval-seed", type=nonneg_int, default=EVAL_SEED, help="first held-out seed"
    )
    parser.add_argument(
        "--checkpoint-freq", type=nonneg_int, default=0,
        help="env steps between checkpoints (0: off)",
    )  # fmt: skip
    parser.add_argument(
        "--init", choices=("none", "bc"), default="none", help="bc: clone --demos first"
    )
    parser.add_argument("--demos", type=existing_file, default=None, help="npz from `sgc demos`")
    parser.add_argument("--bc-epochs", type=nonneg_int, default=30, help="behaviour-cloning epochs")
    parser.add_argument(
        "--bc-log-std", type=float, default=-2.0, help="PPO exploration after cloning"
    )
    parser.add_argument(
        "--critic-warmup", type=nonneg_int, default=0,
        help="env steps of RL with the actor frozen, so the critic learns the clone first",
    )  # fmt: skip
    parser.add_argument(
        "--dagger-rounds", type=nonneg_int, default=0, help="DAgger rounds after cloning"
    )
    parser.add_argument(
        "--dagger-episodes", type=positive_int, default=20, help="rollouts per DAgger round"
    )
    add_push_arguments(parser)
    parser.add_argument(
        "--hyperparams", type=existing_dir, default=None,
        help="folder of <algo>.yml (default: the packaged baselines/hyperparams/)",
    )  # fmt: skip
    parser.add_argument(
        "--env-kwargs", type=env_kwargs, default=None, help="JSON dict passed to gym.make"
    )
    parser.add_argument("--device", default="cpu", help="torch device")
    parser.add_argument(
        "--vec", choices=("batched", "dummy", "subproc"), default=None,
        help="training envs: batched (one PyBullet world, the default), dummy or subproc "
        "(SB3's, of single envs); the same seeds give the same run with batched and dummy",
    )  # fmt: skip
    parser.add_argument("--verbose", type=nonneg_int, default=0, help="SB3 verbosity (0, 1, 2)")


def run(args: argparse.Namespace) -> int:
    from baselines.agents.budget import whole_rollouts
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.agents.train import TrainConfig, record_run_folder, train
    from baselines.cli.console import print_training

    known_env_id(args.env)
    if args.init == "bc" and args.demos is None:
        raise UsageError("--init bc needs --demos (an npz from `sgc demos`)")
    try:  # parsed once, here, for the rounding below and for train()
        hp = load_hyperparams(args.algo, args.env, args.hyperparams)
    except ValueError:
        hp = None  # train() reports a bad algo, env or hyperparameter file with its own message
    timesteps = args.timesteps
    if timesteps and hp is not None:
        timesteps = whole_rollouts(timesteps, args.algo, hp)
    if timesteps != args.timesteps:
        print(f"note: --timesteps {args.timesteps} rounds up to {timesteps} "
              f"({args.algo} trains whole rollouts: n_envs x n_steps)")  # fmt: skip
    pushes = {f"push_{key}": value for key, value in push_options(args).items()}
    cfg = TrainConfig(
        algo=args.algo, env_id=args.env, seed=args.seed, timesteps=timesteps,
        out=args.out, progress=args.progress, eval_freq=args.eval_freq,
        eval_episodes=args.eval_episodes, eval_seed=args.eval_seed, init=args.init,
        demos=args.demos, bc_epochs=args.bc_epochs, bc_log_std=args.bc_log_std,
        critic_warmup=args.critic_warmup,
        dagger_rounds=args.dagger_rounds, dagger_episodes=args.dagger_episodes,
        hyperparams_dir=args.hyperparams, env_kwargs=args.env_kwargs or {}, device=args.device,
        checkpoint_freq=args.checkpoint_freq, verbose=args.verbose, vec=args.vec,
        time_budget_s=args.time_budget, eval_every_s=args.eval_every_s,
        command=shlex.join(["sgc", *sys.argv[1:]]), **pushes,
    )  # fmt: skip
    try:
        if args.out is None:
            result = train(cfg, hp)
        else:  # staged next to --out: an interrupted run leaves the earlier run's files whole
            with staged_output(args.out, keep_on_failure=("checkpoints",)) as stage:
                result = train(replace(cfg, out=stage), hp)
                record_run_folder(stage, args.out)
            result.model_path = args.out / "final_model.zip"
    except ValueError as exc:  # a bad input file (demos, hyperparameters) found while training
        raise UsageError(str(exc)) from None
    print_training(result, cfg, args.out)
    return 0
