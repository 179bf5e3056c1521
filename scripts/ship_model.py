"""Ship a trained model: copy it into baselines/checkpoints/ and write its manifest entry.

From a run folder (``sgc train --out DIR`` or a ``sgc benchmark`` run)::

    python scripts/ship_model.py --run runs/benchmark/point/runs/SGCPoint-v1/ppo/seed0 \
        --name ppo_SGCPoint-v1 [--which best|final] [--episodes 50] [--seed 20000]

or, for a model already in the folder whose run is gone, the facts by hand::

    python scripts/ship_model.py --existing ppo_dagger_SGCPoint-v1.zip --env SGCPoint-v1 \
        --algo ppo --demonstrations --timesteps 0 --train-seed 0 --wall-time 139 \
        --command "sgc train ..." [--episodes 50] [--seed 10000]

Either way the model is scored with the harness on held-out seeds, the entry replaces
any entry for the same file, and the model card is written beside the model
(``baselines/zoo/cards.py``; ``--card-episodes 0`` skips it, ``sgc card STEM`` redoes it).
"""

from __future__ import annotations

import argparse
import json

from baselines.zoo.cards import write_model_card
from baselines.zoo.manifest import CHECKPOINTS, held_out_result, ship_model, write_entry


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--run", help="run folder with config.json and the models")
    source.add_argument("--existing", help="file name of a model already in the checkpoints")
    parser.add_argument("--name", help="--run: stem of the shipped file")
    parser.add_argument("--which", choices=("best", "final"), default="best")
    parser.add_argument("--episodes", type=int, default=50, help="held-out episodes")
    parser.add_argument("--seed", type=int, default=20_000, help="first held-out seed")
    parser.add_argument("--env", help="--existing: env id")
    parser.add_argument("--algo", help="--existing: ppo, sac, td3, her")
    parser.add_argument("--demonstrations", action="store_true", help="--existing: BC/DAgger")
    parser.add_argument("--timesteps", type=int, default=0, help="--existing: RL env steps")
    parser.add_argument("--train-seed", type=int, default=0, help="--existing: training seed")
    parser.add_argument("--wall-time", type=float, help="--existing: training wall time (s)")
    parser.add_argument("--command", help="--existing: the command that trained it")
    parser.add_argument("--card-episodes", type=int, default=10,
                        help="held-out episodes the model card evaluates (0: no card)")  # fmt: skip
    args = parser.parse_args()
    if args.run:
        if not args.name:
            parser.error("--run needs --name")
        entry = ship_model(args.run, args.name, which=args.which, episodes=args.episodes,
                           seed=args.seed)  # fmt: skip
    else:
        needed = {"--env": args.env, "--algo": args.algo, "--wall-time": args.wall_time,
                  "--command": args.command}  # fmt: skip
        missing = [flag for flag, value in needed.items() if value is None]
        if missing:
            parser.error(f"--existing needs {', '.join(missing)}")
        model = CHECKPOINTS / args.existing
        if not model.is_file():
            parser.error(f"--existing: no {model}")
        entry = {
            "file": args.existing, "env_id": args.env, "algo": args.algo,
            "demonstrations": args.demonstrations, "timesteps": args.timesteps,
            "seed": args.train_seed, "wall_time_s": args.wall_time, "command": args.command,
            "result": held_out_result(model, args.env, args.episodes, args.seed),
        }  # fmt: skip
        write_entry(entry)
    print(json.dumps(entry, indent=1))
    if args.card_episodes > 0:
        print(write_model_card(entry, episodes=args.card_episodes))


if __name__ == "__main__":
    main()
