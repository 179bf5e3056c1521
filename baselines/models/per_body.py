"""One network for every body: a shared per-body actor-critic as an SB3 policy class.

The bodies of an SGC scene never interact, and every body's goals enter the observation in
the same per-body block, so the three-rod problem is three copies of one 6-D problem.
:class:`PerBodyPolicy` maps each body's slice of the features through the same MLP to that
body's 6-D action and concatenates the actions. The features are the env's own learner view
(:class:`LearnerViewBodies`: the body's two tracks of the view, 23 entries each, and the
episode's time fraction); the critic averages per-body values (the env's reward is a mean
over bodies). Three bodies give three samples of the shared net per env step, and the same
weights run on any number of bodies.

**Actions in acceleration units.** The net's output is a desired acceleration in units of
``REFERENCE_ACCELERATION`` (m/s^2 for the force, rad/s^2 for the torque; the action scale of
``SGCRod-v1``, where the gain is ~1), which a fixed per-body gain turns into the env's action,
plus the action that holds the body against gravity. Why: the action scale differs between
scenes (``SGCThreeRodsRandom`` has twice the paper scene's force and torque limits, the rod
preset a third of its angular acceleration), the agent does not observe the limits, and a net
trained on one scale drives the other at the wrong gain and hover. The gains are read from an
env (:func:`body_gains`: mass, force and torque limits, inertia, gravity, the facts the expert
also reads), at construction from the env id named in ``gains_env`` (saved in the ``.zip`` with
the other policy kwargs) and again, for the env a saved model is loaded on, by
:meth:`PerBodyPolicy.bind_env` (:func:`baselines.models.model_files.load_sb3_model` calls it).
"""

from __future__ import annotations

import re
import warnings
from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np
import torch as th
from stable_baselines3.common.distributions import DiagGaussianDistribution, Distribution
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from stable_baselines3.common.type_aliases import PyTorchObs
from torch import nn

from baselines.common.env_model import EnvModel
from sgc_env.envs.learner_view import LEARNER_BODY_SIZE, LEARNER_TRACK_SIZE, learner_size
from sgc_env.scenario.bounded import escaped

__all__ = [
    "BODY_ACTIONS",
    "BODY_FEATURES",
    "LearnerViewBodies",
    "REFERENCE_ACCELERATION",
    "PerBodyPolicy",
    "body_gains",
]

BODY_ACTIONS = 6
_SGC_ID = re.compile(r"SGC[A-Za-z0-9]{1,60}-v\d{1,4}")
"""The ids ``gains_env`` may name: this package's (registered or renamed), no other env's."""
BODY_FEATURES = 2 * LEARNER_TRACK_SIZE + 1
"""What the shared net reads of each body from :class:`LearnerViewBodies`."""
REFERENCE_ACCELERATION = 100.0
"""m/s^2 and rad/s^2 per unit of the net's output (SGCRod-v1's own action scale)."""


def body_gains(env: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(gain, offset)``, each ``(n_bodies, 6)``: ``action = gain * output + offset``.

    Force: ``gain = REFERENCE_ACCELERATION m / force_limit``, offset ``-m g / force_limit``
    (the hover). Torque: an action of 1 gives ``torque_limit / max(I)`` about any axis
    (docs/environments.md), so ``gain = REFERENCE_ACCELERATION max(I) / torque_limit``.
    """
    base = getattr(env, "unwrapped", env)
    if getattr(base, "scenario", None) is None:
        base.reset(seed=0)
    scenario = base.scenario
    n = len(scenario.bodies)
    shape = getattr(base.action_space, "shape", None)
    if shape != (BODY_ACTIONS * n,):
        raise ValueError(
            f"PerBodyPolicy needs {BODY_ACTIONS} actions per body (force and torque); "
            f"{type(base).__name__} has action shape {shape} for {n} bodies"
        )
    model = EnvModel.from_env(base)
    gravity = np.asarray(model.gravity, dtype=np.float64)
    gain, offset = np.zeros((n, BODY_ACTIONS)), np.zeros((n, BODY_ACTIONS))
    for i, body in enumerate(model.bodies):
        gain[i, :3] = REFERENCE_ACCELERATION * body.mass / body.force_limit
        gain[i, 3:] = REFERENCE_ACCELERATION * max(body.inertia) / body.torque_limit
        offset[i, :3] = -body.mass * gravity / body.force_limit
    return gain, offset


class LearnerViewBodies(BaseFeaturesExtractor):
    """The env's learner view regrouped per body: each body's two tracks (23 entries each) and
    the episode's time fraction, ``(batch, n * 47)``. The view's hovering action is dropped:
    the policy's action map adds the hover (:func:`body_gains`), so the net's output means the
    same acceleration on every scene."""

    def __init__(self, observation_space: gym.spaces.Space) -> None:
        shape = getattr(observation_space, "shape", None)
        size = int(shape[0]) if isinstance(observation_space, gym.spaces.Box) and shape else 0
        n_bodies = (size - 1) // LEARNER_BODY_SIZE
        if len(shape or ()) != 1 or n_bodies < 1 or learner_size(n_bodies) != size:
            raise ValueError(
                f"LearnerViewBodies needs the learner view (n * {LEARNER_BODY_SIZE} + 1 "
                f"entries), got {observation_space}"
            )
        super().__init__(observation_space, n_bodies * BODY_FEATURES)
        self.n_bodies = n_bodies

    def forward(self, observations: th.Tensor) -> th.Tensor:
        obs = observations.float()
        bodies = obs[:, :-1].reshape(obs.shape[0], self.n_bodies, LEARNER_BODY_SIZE)
        clock = obs[:, -1:].unsqueeze(1).expand(-1, self.n_bodies, -1)
        return th.cat([bodies[..., : 2 * LEARNER_TRACK_SIZE], clock], dim=-1).flatten(1)


_BODY_INPUTS: dict[type, tuple[int, int]] = {LearnerViewBodies: (BODY_FEATURES, BODY_FEATURES)}
"""Per features extractor: the features per body it hands out, and how many the net reads."""


def _mlp(sizes: list[int], activation: type[nn.Module]) -> nn.Sequential:
    layers: list[nn.Module] = []
    for a, b in zip(sizes[:-1], sizes[1:], strict=True):
        layers += [nn.Linear(a, b), activation()]
    return nn.Sequential(*layers)


class PerBodyExtractor(nn.Module):
    """The shared per-body MLPs: ``(batch, n * stride)`` features, of which the first ``width``
    of each body's are read, to ``(batch, n * latent)``;
    with ``skip`` the actor's latent also carries the body's features (why: a fixed linear law
    on them meets every three-rod goal, docs/agents.md, so the head can start from one)."""

    def __init__(
        self,
        n_bodies: int,
        pi: list[int],
        vf: list[int],
        activation: type[nn.Module],
        skip: bool = False,
        width: int = BODY_FEATURES,
    ) -> None:
        super().__init__()
        self.n_bodies = n_bodies
        self.width = width
        self.skip = skip and bool(pi)
        self.policy_net = _mlp([width, *pi], activation)
        self.value_net = _mlp([width, *vf], activation)
        self.latent_pi = (pi[-1] + width * self.skip) if pi else width
        self.latent_vf = vf[-1] if vf else width
        self.latent_dim_pi = n_bodies * self.latent_pi
        self.latent_dim_vf = n_bodies * self.latent_vf

    def _bodies(self, features: th.Tensor) -> th.Tensor:
        return features.reshape(features.shape[0], self.n_bodies, -1)[..., : self.width]

    def forward(self, features: th.Tensor) -> tuple[th.Tensor, th.Tensor]:
        return self.forward_actor(features), self.forward_critic(features)

    def forward_actor(self, features: th.Tensor) -> th.Tensor:
        bodies = self._bodies(features)
        latent = self.policy_net(bodies)
        if self.skip:  # the head also reads the features: a linear law is one layer away
            latent = th.cat([latent, bodies], dim=-1)
        return latent.flatten(start_dim=1)

    def forward_critic(self, features: th.Tensor) -> th.Tensor:
        return self.value_net(self._bodies(features)).flatten(start_dim=1)


class PerBodyHead(nn.Module):
    """One linear map per body (shared weights), then ``gain * output + offset``."""

    gain: th.Tensor
    offset: th.Tensor

    def __init__(self, n_bodies: int, latent: int, out: int, gain: Any, offset: Any) -> None:
        super().__init__()
        self.n_bodies = n_bodies
        self.linear = nn.Linear(latent, out)
        self.register_buffer("gain", th.as_tensor(np.asarray(gain), dtype=th.float32))
        self.register_buffer("offset", th.as_tensor(np.asarray(offset), dtype=th.float32))

    def forward(self, latent: th.Tensor) -> th.Tensor:
        y = self.linear(latent.reshape(latent.shape[0], self.n_bodies, -1))
        return (y * self.gain + self.offset).flatten(start_dim=1)


class PerBodyPolicy(ActorCriticPolicy):
    """:class:`ActorCriticPolicy` with one shared net per body (module docstring).

    ``gains_env``: the env id whose bodies set the action gains at construction (None: gain 1,
    no hover, ``SGCRod-v1``'s scale without gravity); ``bind_env`` resets them for another env.
    ``skip``: the action head reads the body's features beside the last hidden layer.
    The features extractor is :class:`LearnerViewBodies` (the env's learner view). The action
    noise's log std is shared per action component across bodies (6 parameters) and, like the
    mean, in acceleration units (``log_std_init=-3``: 5 m/s^2 and 5 rad/s^2 on every scene).
    """

    def __init__(
        self,
        observation_space: gym.spaces.Space,
        action_space: gym.spaces.Space,
        lr_schedule: Any,
        *args: Any,
        gains_env: str | None = None,
        skip: bool = False,
        **kwargs: Any,
    ) -> None:
        kwargs.setdefault("features_extractor_class", LearnerViewBodies)
        if kwargs["features_extractor_class"] not in _BODY_INPUTS:
            raise ValueError("PerBodyPolicy: features_extractor_class must be LearnerViewBodies")
        if kwargs.get("use_sde"):
            raise ValueError("PerBodyPolicy: use_sde is not supported")
        self.gains_env = gains_env
        self.skip = skip
        n = int(np.prod(action_space.shape or (0,))) // BODY_ACTIONS
        box = isinstance(action_space, gym.spaces.Box)
        if not box or n < 1 or action_space.shape != (BODY_ACTIONS * n,):
            raise ValueError(f"PerBodyPolicy needs a Box of 6 actions per body, got {action_space}")
        self.n_bodies = n
        self._initial_gains = (np.ones((n, BODY_ACTIONS)), np.zeros((n, BODY_ACTIONS)))
        import sgc_env  # registers the ids

        if gains_env is not None and not (isinstance(gains_env, str)
                                          and _SGC_ID.fullmatch(gains_env)):  # fmt: skip
            # a file names it: only an SGC env is built here, never another registered one
            raise ValueError(f"PerBodyPolicy: gains_env must be an SGC env id "
                             f"({', '.join(sgc_env.ENV_IDS)}), got {escaped(repr(gains_env))}")
        if gains_env is not None and gains_env not in gym.registry:
            # a saved model whose id was renamed still loads: its gains come back from the
            # file's buffers, and the loader re-binds them to the env it is loaded on
            warnings.warn(
                f"PerBodyPolicy: gains_env {gains_env!r} is not registered; unit "
                "gains until bind_env or the saved buffers set them",
                stacklevel=2,
            )
        elif gains_env is not None:
            env = gym.make(gains_env)
            try:
                self._initial_gains = body_gains(env)
            finally:
                env.close()
        super().__init__(observation_space, action_space, lr_schedule, *args, **kwargs)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.update(gains_env=self.gains_env, skip=self.skip)
        return data

    def _build_mlp_extractor(self) -> None:
        extractor = type(self.features_extractor)
        stride, width = _BODY_INPUTS[extractor]
        if self.features_dim != self.n_bodies * stride:
            raise ValueError(
                f"PerBodyPolicy: {self.features_dim} features for {self.n_bodies} bodies; "
                f"expected {extractor.__name__}'s {stride} per body"
            )
        arch = self.net_arch
        pi, vf = (arch["pi"], arch["vf"]) if isinstance(arch, dict) else (arch, arch)
        self.mlp_extractor = PerBodyExtractor(  # type: ignore[assignment]
            self.n_bodies, list(pi), list(vf), self.activation_fn, self.skip, width
        )

    def _build(self, lr_schedule: Any) -> None:
        if not isinstance(self.action_dist, DiagGaussianDistribution):
            raise ValueError("PerBodyPolicy: needs a Gaussian action distribution (a Box)")
        self._build_mlp_extractor()
        ex: PerBodyExtractor = self.mlp_extractor  # type: ignore[assignment]
        gain, offset = self._initial_gains
        self.action_net = PerBodyHead(self.n_bodies, ex.latent_pi, BODY_ACTIONS, gain, offset)
        n = self.n_bodies
        self.value_net = PerBodyHead(  # type: ignore[assignment]
            n, ex.latent_vf, 1, np.ones((n, 1)), np.zeros((n, 1))
        )
        self.log_std = nn.Parameter(th.full((BODY_ACTIONS,), float(self.log_std_init)))
        if self.ortho_init:
            gains = {ex: np.sqrt(2), self.action_net: 0.01, self.value_net: 1.0}
            for module, g in gains.items():
                module.apply(partial(self.init_weights, gain=g))
        self.optimizer = self.optimizer_class(  # type: ignore[call-arg]
            self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
        )

    def _get_action_dist_from_latent(self, latent_pi: th.Tensor) -> Distribution:
        mean_actions = self.action_net(latent_pi)
        head: PerBodyHead = self.action_net  # type: ignore[assignment]
        log_std = (self.log_std + th.log(head.gain)).flatten()  # noise in acceleration units
        return self.action_dist.proba_distribution(mean_actions, log_std)

    def forward(
        self, obs: th.Tensor, deterministic: bool = False
    ) -> tuple[th.Tensor, th.Tensor, th.Tensor]:
        actions, values, log_prob = super().forward(obs, deterministic)
        return actions, self._mean_value(values), log_prob

    def evaluate_actions(
        self, obs: PyTorchObs, actions: th.Tensor
    ) -> tuple[th.Tensor, th.Tensor, th.Tensor | None]:
        values, log_prob, entropy = super().evaluate_actions(obs, actions)
        return self._mean_value(values), log_prob, entropy

    def predict_values(self, obs: PyTorchObs) -> th.Tensor:
        return self._mean_value(super().predict_values(obs))

    @staticmethod
    def _mean_value(values: th.Tensor) -> th.Tensor:
        """Per-body values ``(batch, n)`` to the env's value ``(batch, 1)``."""
        return values.mean(dim=1, keepdim=True)

    def bind_env(self, env: Any) -> None:
        """Set the action gains and hover from ``env``'s bodies (see :func:`body_gains`)."""
        gain, offset = body_gains(env)
        if gain.shape[0] != self.n_bodies:
            raise ValueError(
                f"PerBodyPolicy: built for {self.n_bodies} bodies, the env has {gain.shape[0]}"
            )
        head: PerBodyHead = self.action_net  # type: ignore[assignment]
        head.gain.copy_(th.as_tensor(gain, dtype=th.float32))
        head.offset.copy_(th.as_tensor(offset, dtype=th.float32))
