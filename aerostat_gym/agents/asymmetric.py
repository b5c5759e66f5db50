"""An asymmetric actor-critic for PPO: the critic reads the privileged full state, the actor only
the channels a deployed controller has.

The value function is a training device: it is thrown away at deployment, so it may read what
no sensor gives (the environment's ``observation="full"`` layout: the standard channels, the
episode's mean wind speed and the full simulator state). Knowing the true tether shape and
the aerostat's true attitude removes the sensor noise from the value targets' baseline, so the
advantage estimates that train the actor are less noisy. The actor reads only
``actor_channels`` of the observation (the standard channels, and the residual base's estimate
features when the residual observes them), so the trained policy acts on equal information with
the output-feedback baselines: its action does not depend on the other channels at all
(tested).

- :func:`actor_channels`: the indices the actor reads in the training observation layout.
- :class:`AsymmetricActorCriticPolicy`: SB3's ``ActorCriticPolicy`` whose MLP extractor
  (:class:`AsymmetricMlpExtractor`) selects the actor's channels before its network.

Stable-Baselines3 and torch are optional dependencies: the classes are built on first use
(:func:`policy_class`), and the module attribute ``AsymmetricActorCriticPolicy``, through which
a saved model names its policy class, resolves to the same class.
"""

from __future__ import annotations

from ..envs.spaces import N_OBS

#: Name of the policy class, as saved models refer to it (``aerostat_gym.agents.asymmetric.``).
POLICY_CLASS = "AsymmetricActorCriticPolicy"


def actor_channels(width: int, n_features: int = 0) -> list[int]:
    """The channels the actor reads in an observation of ``width`` channels: the standard ones
    (the first N_OBS) and the last ``n_features`` (the residual base's estimate, appended after
    the environment's channels)."""
    return list(range(N_OBS)) + list(range(width - n_features, width))


def policy_class():
    """The SB3 policy class (built once; importing torch and Stable-Baselines3)."""
    cached = globals().get(POLICY_CLASS)
    if cached is not None:
        return cached
    import torch
    from stable_baselines3.common.policies import ActorCriticPolicy
    from stable_baselines3.common.torch_layers import MlpExtractor

    class AsymmetricMlpExtractor(torch.nn.Module):
        """SB3's MlpExtractor with the actor's network on ``channels`` of the features and
        the critic's on all of them."""

        def __init__(self, feature_dim: int, net_arch, activation_fn, device, channels):
            super().__init__()
            self.register_buffer("channels", torch.as_tensor(channels, dtype=torch.long))
            self.actor = MlpExtractor(len(channels), net_arch, activation_fn, device)
            self.critic = MlpExtractor(feature_dim, net_arch, activation_fn, device)
            self.latent_dim_pi = self.actor.latent_dim_pi
            self.latent_dim_vf = self.critic.latent_dim_vf

        def forward(self, features):
            return self.forward_actor(features), self.forward_critic(features)

        def forward_actor(self, features):
            return self.actor.forward_actor(features.index_select(-1, self.channels))

        def forward_critic(self, features):
            return self.critic.forward_critic(features)

    class AsymmetricActorCriticPolicy(ActorCriticPolicy):
        """ActorCriticPolicy (flattened observation) whose actor reads only
        ``actor_channels``."""

        def __init__(self, *args, actor_channels=None, **kwargs):
            if not actor_channels:
                raise ValueError(f"{POLICY_CLASS} needs actor_channels")
            self.actor_channels = [int(c) for c in actor_channels]
            super().__init__(*args, **kwargs)

        def _build_mlp_extractor(self) -> None:
            self.mlp_extractor = AsymmetricMlpExtractor(self.features_dim, self.net_arch,
                                                        self.activation_fn, self.device,
                                                        self.actor_channels)

        def _get_constructor_parameters(self) -> dict:
            return {**super()._get_constructor_parameters(),
                    "actor_channels": self.actor_channels}

    # saved models name the class by this module and name, and load it through __getattr__
    AsymmetricActorCriticPolicy.__module__ = __name__
    AsymmetricActorCriticPolicy.__qualname__ = POLICY_CLASS
    globals()[POLICY_CLASS] = AsymmetricActorCriticPolicy
    return AsymmetricActorCriticPolicy


def __getattr__(name: str):
    if name == POLICY_CLASS:
        return policy_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
