"""The benchmark grid: recipes x env ids x training seeds, checked before anything runs.

A recipe is an algorithm with its hyperparameter folder (rl-zoo3 ``<algo>.yml``), optional
env kwargs (e.g. a reward mode) and optional ``sgc train`` options (``init: bc``, ``demos``,
``dagger_rounds`` ...: with demonstrations). A run is one recipe on one env with one seed;
it lives in ``<root>/runs/<env>/<recipe>/seed<N>/`` and is finished when its
``result.json`` exists there.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shlex
import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from baselines.common.value_types import describe, matches
from sgc_env.scenario.bounded import escaped, load_yaml, read_text

__all__ = [
    "EVAL_SEED",
    "TEST_SEED",
    "Recipe",
    "RunSpec",
    "build_grid",
    "load_recipes",
    "recipes_from_algos",
    "train_command",
]

EVAL_SEED = 10_000
"""First seed of the learning-curve evaluations (they also pick ``best_model.zip``)."""
TEST_SEED = 20_000
"""First held-out seed of the final scoring, disjoint from the seeds that picked the best."""

_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*")
#: What a recipe's ``demos`` path may say about its run (nothing else in braces).
_PLACEHOLDER = re.compile(r"\{(env_id|seed)\}")
#: ``sgc train`` options a recipe may set (TrainConfig fields the grid does not own).
_OWNED = {
    "algo", "env_id", "seed", "out", "eval_freq", "eval_episodes", "eval_seed", "command",
    "progress", "verbose", "env_kwargs", "hyperparams_dir", "timesteps", "time_budget_s",
    "eval_every_s",
}  # fmt: skip
_RECIPE_FIELDS = {"name", "algo", "hyperparams", "timesteps", "time_budget_s", "env_kwargs",
                  "train", "envs"}  # fmt: skip
#: TrainConfig field -> ``sgc train`` flag, where the two are not spelled alike.
_FLAGS = {"env_id": "--env", "hyperparams_dir": "--hyperparams", "time_budget_s": "--time-budget"}


def _train_fields() -> dict[str, Any]:
    from baselines.agents.train import TrainConfig

    return {f.name: f for f in dataclasses.fields(TrainConfig)}


def _check_train_options(train: Mapping[str, Any], where: str) -> None:
    """Each option's value against ``TrainConfig``'s type hints; ``demos`` placeholders."""
    from baselines.agents.train import TrainConfig

    hints = typing.get_type_hints(TrainConfig)
    for name, value in train.items():
        if matches(value, hints[name]) is False:
            raise ValueError(f"{where}: train option {name} must be {describe(hints[name])}, "
                             f"got {value!r}")  # fmt: skip
    demos = train.get("demos")
    if isinstance(demos, str) and ("{" in _PLACEHOLDER.sub("", demos)
                                   or "}" in _PLACEHOLDER.sub("", demos)):  # fmt: skip
        raise ValueError(f"{where}: demos {demos!r}: the only placeholders are {{env_id}} and "
                         "{seed}")  # fmt: skip


@dataclass(frozen=True)
class Recipe:
    """One way to train: algorithm, hyperparameter folder, env kwargs, extra train options."""

    name: str
    algo: str
    hyperparams: str | None = None
    timesteps: int | None = None
    env_kwargs: Mapping[str, Any] = field(default_factory=dict)
    train: Mapping[str, Any] = field(default_factory=dict)
    envs: tuple[str, ...] = ()
    """The env ids this recipe runs on (empty: every ``--env``); e.g. HER's goal-conditioned id."""
    time_budget_s: float | None = None
    """Seconds of training per run (``timesteps`` is then the upper bound); None: no budget."""

    def runs_on(self, env_id: str) -> bool:
        return not self.envs or env_id in self.envs

    @property
    def demonstrations(self) -> bool:
        """True when the recipe starts from expert demonstrations (BC, DAgger)."""
        return self.train.get("init", "none") == "bc"

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name, "algo": self.algo, "hyperparams": self.hyperparams,
            "timesteps": self.timesteps, "env_kwargs": dict(self.env_kwargs),
            "train": dict(self.train), "envs": list(self.envs),
            "demonstrations": self.demonstrations, "time_budget_s": self.time_budget_s,
        }  # fmt: skip


@dataclass(frozen=True)
class RunSpec:
    """One training run of the grid and how it is scored."""

    recipe: Recipe
    env_id: str
    seed: int
    eval_freq: int
    curve_episodes: int
    eval_episodes: int
    eval_seed: int = EVAL_SEED
    test_seed: int = TEST_SEED

    @property
    def run_id(self) -> str:
        return f"{self.env_id}/{self.recipe.name}/seed{self.seed}"

    def folder(self, root: str | Path) -> Path:
        return Path(root) / "runs" / self.env_id / self.recipe.name / f"seed{self.seed}"

    def train_options(self, out: str | Path | None) -> dict[str, Any]:
        """Keyword arguments of :class:`~baselines.agents.train.TrainConfig` for this run."""
        train = {k: v for k, v in self.recipe.train.items()}
        demos = train.get("demos")
        if isinstance(demos, str):
            values = {"env_id": self.env_id, "seed": str(self.seed)}
            train["demos"] = _PLACEHOLDER.sub(lambda m: values[m[1]], demos)
        return {
            "algo": self.recipe.algo, "env_id": self.env_id, "seed": self.seed,
            "timesteps": self.recipe.timesteps, "out": None if out is None else str(out),
            "time_budget_s": self.recipe.time_budget_s,
            "eval_freq": self.eval_freq, "eval_episodes": self.curve_episodes,
            "eval_seed": self.eval_seed, "hyperparams_dir": self.recipe.hyperparams,
            "env_kwargs": dict(self.recipe.env_kwargs), **train,
        }  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        return {
            "run_id": self.run_id, "recipe": self.recipe.to_dict(), "env_id": self.env_id,
            "seed": self.seed, "eval_freq": self.eval_freq,
            "curve_episodes": self.curve_episodes, "eval_episodes": self.eval_episodes,
            "eval_seed": self.eval_seed, "test_seed": self.test_seed,
        }  # fmt: skip

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunSpec:
        r = dict(data["recipe"])
        r.pop("demonstrations", None)
        r["envs"] = tuple(r.get("envs") or ())
        return cls(
            recipe=Recipe(**r), env_id=data["env_id"], seed=int(data["seed"]),
            eval_freq=int(data["eval_freq"]), curve_episodes=int(data["curve_episodes"]),
            eval_episodes=int(data["eval_episodes"]), eval_seed=int(data["eval_seed"]),
            test_seed=int(data["test_seed"]),
        )  # fmt: skip


def train_command(options: Mapping[str, Any]) -> str:
    """The ``sgc train`` command line that reproduces a run from its TrainConfig options."""
    fields = _train_fields()
    argv = ["sgc", "train"]
    for name, value in options.items():
        default = fields[name].default
        if name == "command" or value is None or value == default or value == {}:
            continue
        flag = _FLAGS.get(name, "--" + name.replace("_", "-"))
        if isinstance(value, bool):
            argv.append(flag)
        elif isinstance(value, Mapping):
            argv += [flag, json.dumps(dict(value), sort_keys=True)]
        else:
            argv += [flag, str(value)]
    return shlex.join(argv)


def _check_name(name: Any, where: str) -> str:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ValueError(f"{where}: recipe name must be letters, digits and _.+- , got {name!r}")
    return name


def _recipe(entry: Any, where: str) -> Recipe:
    from baselines.agents.budget import check_time_budget
    from baselines.agents.train import ALGORITHMS
    from baselines.common.env_kwargs import check_kwarg_values

    if not isinstance(entry, Mapping):
        raise ValueError(f"{where}: expected a mapping, got {type(entry).__name__}")
    unknown = set(entry) - _RECIPE_FIELDS
    if unknown:
        raise ValueError(f"{where}: unknown recipe field(s) {sorted(unknown)}")
    algo = entry.get("algo")
    if algo not in ALGORITHMS:
        raise ValueError(f"{where}: algo must be one of {ALGORITHMS}, got {algo!r}")
    name = _check_name(entry.get("name", algo), where)
    timesteps = entry.get("timesteps")
    if timesteps is not None and (not matches(timesteps, int) or timesteps < 0):
        raise ValueError(f"{where}: timesteps must be an integer >= 0, got {timesteps!r}")
    budget = check_time_budget(entry.get("time_budget_s"), f"{where}: time_budget_s")
    env_kwargs = entry.get("env_kwargs") or {}
    train = entry.get("train") or {}
    if not isinstance(env_kwargs, Mapping) or not isinstance(train, Mapping):
        raise ValueError(f"{where}: env_kwargs and train must be mappings")
    check_kwarg_values(env_kwargs, f"{where}: env_kwargs")
    allowed = set(_train_fields()) - _OWNED
    bad = set(train) - allowed
    if bad:
        raise ValueError(f"{where}: train option(s) {sorted(bad)} unknown or set by the grid; "
                         f"allowed: {sorted(allowed)}")  # fmt: skip
    _check_train_options(train, where)
    hyperparams = entry.get("hyperparams")
    if hyperparams is not None and not isinstance(hyperparams, str):
        raise ValueError(f"{where}: hyperparams must be a folder name, got {hyperparams!r}")
    if hyperparams is not None and not Path(hyperparams).is_dir():
        raise ValueError(f"{where}: hyperparams folder {hyperparams!r} does not exist")
    envs = entry.get("envs") or []
    if isinstance(envs, str) or not isinstance(envs, list):
        raise ValueError(f"{where}: envs must be a list of env ids, got {envs!r}")
    from sgc_env import check_env_id

    for env_id in envs:
        check_env_id(env_id, f"{where}: envs")
    return Recipe(name, algo, hyperparams, timesteps, dict(env_kwargs), dict(train), tuple(envs),
                  budget)  # fmt: skip


def load_recipes(path: str | Path) -> list[Recipe]:
    """Recipes from a YAML file: ``recipes: [{name, algo, hyperparams, timesteps, ...}]``.

    Relative ``hyperparams`` folders are read relative to the file.
    """
    file = Path(path)
    if not file.is_file():
        raise ValueError(f"--recipes: no file {escaped(repr(str(path)))}")
    where = f"--recipes: {escaped(file)}"
    data = load_yaml(read_text(file, "--recipes:"), where)
    entries = data.get("recipes") if isinstance(data, Mapping) else None
    if not isinstance(entries, list) or not entries:
        raise ValueError(f"--recipes: {file}: expected a non-empty list under 'recipes:'")
    recipes = []
    for i, entry in enumerate(entries):
        if isinstance(entry, Mapping) and isinstance(entry.get("hyperparams"), str):
            hp = Path(entry["hyperparams"])
            entry = {**entry, "hyperparams": str(hp if hp.is_absolute() else file.parent / hp)}
        recipes.append(_recipe(entry, f"--recipes: {file}: recipe {i}"))
    return recipes


def recipes_from_algos(
    algos: Sequence[str],
    hyperparams: str | None = None,
    env_kwargs: Mapping[str, Any] | None = None,
    timesteps: int | None = None,
    time_budget_s: float | None = None,
) -> list[Recipe]:
    """One recipe per ``--algo``, named after it."""
    return [
        _recipe(
            {
                "algo": a,
                "hyperparams": hyperparams,
                "env_kwargs": dict(env_kwargs or {}),
                "timesteps": timesteps,
                "time_budget_s": time_budget_s,
            },
            f"--algo {a}",
        )  # fmt: skip
        for a in algos
    ]


def build_grid(
    recipes: Sequence[Recipe],
    env_ids: Sequence[str],
    seeds: Sequence[int],
    *,
    eval_freq: int,
    curve_episodes: int,
    eval_episodes: int,
    eval_seed: int = EVAL_SEED,
    test_seed: int = TEST_SEED,
) -> list[RunSpec]:
    """Every (recipe, env, seed), after checking the arguments (``ValueError`` naming them)."""
    from baselines.agents.hyperparams import load_hyperparams
    from baselines.common.env_kwargs import check_env_kwargs
    from sgc_env import check_env_id

    if not recipes:
        raise ValueError("recipes: give --algo or --recipes")
    names = [r.name for r in recipes]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"recipes: name(s) {twice} used more than once")
    if not env_ids:
        raise ValueError("--env: give at least one env id")
    if not seeds or len(set(seeds)) != len(seeds) or min(seeds) < 0:
        raise ValueError(f"--seeds: need distinct seeds >= 0, got {list(seeds)}")
    for name, value in (("--eval-episodes", eval_episodes), ("--curve-episodes", curve_episodes)):
        if value < 1:
            raise ValueError(f"{name} must be >= 1, got {value}")
    if eval_freq < 0:
        raise ValueError(f"--eval-freq must be >= 0, got {eval_freq}")
    if abs(test_seed - eval_seed) < max(eval_episodes, curve_episodes):
        raise ValueError(f"--test-seed {test_seed}: its episodes overlap the curve's seeds from "
                         f"{eval_seed}; held-out scoring needs seeds of its own")  # fmt: skip
    for env_id in env_ids:
        check_env_id(env_id, "--env")
        for recipe in recipes:
            if recipe.runs_on(env_id):
                load_hyperparams(recipe.algo, env_id, recipe.hyperparams)  # fails early, naming it
                check_env_kwargs(env_id, recipe.env_kwargs, f"recipe {recipe.name!r}: env_kwargs")
    for recipe in recipes:
        if not any(recipe.runs_on(e) for e in env_ids):
            raise ValueError(f"recipe {recipe.name!r}: none of its envs {list(recipe.envs)} is "
                             f"in --env {list(env_ids)}")  # fmt: skip
    return [
        RunSpec(r, e, s, eval_freq, curve_episodes, eval_episodes, eval_seed, test_seed)
        for e in env_ids
        for r in recipes
        if r.runs_on(e)
        for s in seeds
    ]
