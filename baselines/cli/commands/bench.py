"""``sgc bench``: how fast the envs run here, each figure against a reference of the same run.

``sgc bench env`` times every registered id against a bare PyBullet loop of its physics
(:mod:`baselines.timing.env_step`); ``sgc bench compare --reference CHECKOUT`` times this
install's envs against another checkout's, interleaved in one process, with the bare loop
beside them (:mod:`baselines.timing.checkouts`).
"""

from __future__ import annotations

import argparse

from baselines.cli.checks import UsageError, existing_dir, known_env_id, positive_int

__all__ = ["add_arguments", "run"]


def _pair(text: str) -> tuple[str, str]:
    new, sep, old = text.partition("=")
    if not sep or not new or not old:
        raise argparse.ArgumentTypeError(f"expected NEW=OLD (two ids), got {text!r}")
    return known_env_id(new), old


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="benchmark", required=True, metavar="BENCHMARK")
    env = sub.add_parser("env", help="every id's step and reset against a bare PyBullet loop")
    env.add_argument("--steps", type=positive_int, default=10000, help="steps timed per id")
    env.add_argument("--resets", type=positive_int, default=1000, help="resets timed per id")
    env.add_argument("--rounds", type=positive_int, default=20,
                     help="interleaved rounds; the best of each is kept")  # fmt: skip
    env.add_argument("--draws", type=positive_int, default=20,
                     help="random-scene resets timed per random-scene id")  # fmt: skip
    env.add_argument("--ids", nargs="+", type=known_env_id, help="only these ids")
    compare = sub.add_parser(
        "compare", help="this install's env step against another checkout's, and a bare loop"
    )
    compare.add_argument("--reference", type=existing_dir, required=True,
                         help="the other checkout (a folder holding its sgc_env/)")  # fmt: skip
    compare.add_argument("--rounds", type=positive_int, default=40, help="interleaved rounds")
    compare.add_argument("--chunk", type=positive_int, default=500, help="steps per timed chunk")
    compare.add_argument("--ids", nargs="+", type=known_env_id,
                         help="only these ids (default: every id both register)")  # fmt: skip
    compare.add_argument(
        "--pair", action="append", type=_pair, default=[], metavar="NEW=OLD",
        help="this install's id NEW against the reference's id OLD (repeatable)",
    )  # fmt: skip


def run(args: argparse.Namespace) -> int:
    if args.benchmark == "env":
        import sgc_env
        from baselines.timing.env_step import env_table

        ids = args.ids or list(sgc_env.ENV_IDS)
        for line in env_table(ids, args.steps, args.resets, args.rounds, args.draws):
            print(line, flush=True)
        return 0
    from baselines.timing.checkouts import compare_checkouts

    if not (args.reference / "sgc_env" / "__init__.py").is_file():
        raise UsageError(f"--reference {args.reference}: holds no sgc_env/ package")
    pairs = [(env_id, env_id) for env_id in args.ids or []] + args.pair or None
    lines = compare_checkouts(args.reference, pairs, args.rounds, args.chunk)
    try:
        print(next(lines), flush=True)  # the ids are checked before the header
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    for line in lines:
        print(line, flush=True)
    return 0
