"""Stable-Baselines3 input and output: saving and loading trained models with their
VecNormalize statistics and wrapper stack, and the :class:`SB3Policy` that runs one like a
baseline.

A model trained with wrappers beyond VecNormalize (``frame_stack``, ``residual``: see
:mod:`aerostat_gym.agents.train`) is saved with ``<stem>_wrappers.json`` beside it
(:func:`wrappers_path`), ``{"frame_stack": K, "residual": {"base": ..., "scale": ...,
"obs_noise": ...[, "deadband": ..., "lowpass": ...]}}``, so that loading it rebuilds the same
observation stack, base policy and command path.

Stable-Baselines3 (and sb3-contrib, for RecurrentPPO) are optional dependencies (the ``train``
extra): they are imported inside the functions that need them.
"""

from __future__ import annotations

import json
import math
import pickle
import warnings
import zipfile
from pathlib import Path

import numpy as np

from ..envs.spaces import N_OBS, as_batch
from ..extras import require
from .state_check import check_state_passed

VECNORM_SUFFIX = "_vecnormalize.pkl"
WRAPPERS_SUFFIX = "_wrappers.json"
#: Wrapper metadata of every model in a folder (a run's checkpoints/).
FOLDER_WRAPPERS = "wrappers.json"
#: What the command low-pass filters: the summed command, or the base's alone (the residual
#: then adds to the filtered base command, unfiltered).
LOWPASS_ON = ("sum", "base")
#: The top-level keys of the wrapper metadata; any other is refused on reading.
WRAPPER_KEYS = frozenset({"frame_stack", "residual"})


class PolicyError(ValueError):
    """A policy that cannot be loaded or does not fit the environment (clear message)."""


def policy_obs(policy, obs: np.ndarray) -> np.ndarray:
    """The observation slice a policy reads (its ``obs_dim``): the standard channels, which
    lead the privileged full set, or the full set itself. A batch of another width, or of a
    layout the policy was not trained for, is refused with the shapes named."""
    need = getattr(policy, "obs_dim", None)
    if obs.ndim != 2:
        raise PolicyError(f"observations must be one vector or a batch (N, channels), got shape "
                          f"{obs.shape}")
    if need is None or need == obs.shape[1]:
        return obs
    if need == N_OBS and obs.shape[1] > N_OBS:
        return obs[:, :N_OBS]
    raise PolicyError(f"the policy expects observations of {need} channels; the environment "
                      f"gives {N_OBS} (observation='standard') or more ('full'), and this batch "
                      f"has {obs.shape[1]}: it was trained for another observation layout")


def to_actions(actions: np.ndarray, single: bool) -> np.ndarray:
    """Actions clipped to [-1, 1] as float32, shape (1,) or (N, 1)."""
    a = np.clip(actions, -1.0, 1.0).astype(np.float32).reshape(-1, 1)
    return a[0] if single else a


def vecnormalize_path(model_path: Path) -> Path:
    """Where the VecNormalize statistics of a saved model live: checkpoints use SB3's
    ``<prefix>_vecnormalize_<steps>_steps.pkl``; our models ``<stem>_vecnormalize.pkl``."""
    model_path = Path(model_path)
    stem = model_path.stem
    if stem.endswith("_steps") and "_" in stem:
        prefix, steps = stem.rsplit("_", 2)[0], stem.rsplit("_", 2)[1]
        return model_path.with_name(f"{prefix}_vecnormalize_{steps}_steps.pkl")
    return model_path.with_name(stem + VECNORM_SUFFIX)


def wrappers_path(model_path: Path) -> Path:
    """Where the wrapper metadata of a saved model lives: ``<stem>_wrappers.json``."""
    model_path = Path(model_path)
    return model_path.with_name(model_path.stem + WRAPPERS_SUFFIX)


def find_in_chain(venv, cls):
    """The first environment of type ``cls`` down a wrapper chain (each wrapper's ``venv``;
    None if there is none)."""
    while venv is not None:
        if isinstance(venv, cls):
            return venv
        venv = getattr(venv, "venv", None)
    return None


def find_vecnormalize(venv):
    """The VecNormalize in a wrapper chain (None if there is none)."""
    from stable_baselines3.common.vec_env import VecNormalize

    return find_in_chain(venv, VecNormalize)


def save_model(model, path: Path, wrappers: dict | None = None) -> None:
    """Save the model, the statistics of the VecNormalize in its environment's wrapper chain (if
    any) and, when ``wrappers`` has a frame stack or a residual base, their metadata beside it."""
    model.save(str(path))
    norm = find_vecnormalize(model.get_env())
    if norm is not None:
        norm.save(str(vecnormalize_path(path)))
    write_wrappers(wrappers_path(path), wrappers)


def write_wrappers(path: Path, wrappers: dict | None) -> None:
    """Write the wrapper metadata worth saving (nothing for a plain model)."""
    wrappers = clean_wrappers(wrappers)
    if wrappers:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(json.dumps(wrappers, indent=2) + "\n")


def clean_wrappers(wrappers: dict | None) -> dict:
    """The metadata worth saving: a frame stack of more than one frame, a residual base."""
    out = {}
    if wrappers and int(wrappers.get("frame_stack") or 1) > 1:
        out["frame_stack"] = int(wrappers["frame_stack"])
    if wrappers and wrappers.get("residual"):
        out["residual"] = dict(wrappers["residual"])
    return out


def _is_recurrent(model) -> bool:
    return type(model).__name__ == "RecurrentPPO"


class SB3Policy:
    """A Stable-Baselines3 model and (optionally) the VecNormalize whose statistics it was
    trained with; observations are normalised the same way before ``model.predict``.

    ``frame_stack`` K > 1 stacks the last K normalised observations (oldest first, the
    newest last, zeros before the episode's first step: SB3's VecFrameStack on top of
    VecNormalize). ``residual`` = (base policy, :class:`CommandShaper`) adds the model's action
    times the shaper's scale to the base policy's (which reads the raw observation and keeps its
    own state), clipped to [-1, 1], low-passed and deadbanded as in training. The state passed
    back and forth is then a dict of the recurrent model's state, the stack, the base policy's
    state and the command filter's; ``episode_start`` resets all four. With
    ``observe_estimate`` the model also reads the base's filter estimate
    (``base.estimate_features``), appended to the raw observation before normalisation, as
    the training wrapper does (:func:`aerostat_gym.agents.residual.residual_vec_env`).
    """

    def __init__(self, model, vecnormalize=None, frame_stack: int = 1, residual=None,
                 observe_estimate: bool = False):
        from stable_baselines3.common.vec_env import VecNormalize

        self.model = model
        self.norm = vecnormalize if isinstance(vecnormalize, VecNormalize) else None
        self.frame_stack = int(frame_stack)
        self.residual = residual
        self.observe_estimate = bool(observe_estimate) and residual is not None
        self.recurrent = _is_recurrent(model)
        frame = int(model.observation_space.shape[0]) // self.frame_stack
        # the environment's channels; the base's estimate features follow them
        self.obs_dim = frame - (residual[0].n_features if self.observe_estimate else 0)
        if self.obs_dim < N_OBS:
            raise PolicyError(f"the model reads {frame} channels per frame: fewer than the "
                              f"{N_OBS} standard channels"
                              + (f" and the base's {residual[0].n_features} estimate features"
                                 if self.observe_estimate else ""))
        self.plain = self.frame_stack == 1 and residual is None and not self.recurrent

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs, single = as_batch(observation, episode_start=episode_start)
        obs = policy_obs(self, obs)
        if self.plain:
            if self.norm is not None:
                obs = self.norm.normalize_obs(obs)
            a, _ = self.model.predict(obs, deterministic=deterministic)
            return to_actions(np.asarray(a).reshape(-1), single), state
        check_state_passed(self, state, episode_start, len(obs), "the base controller's, the "
                           "command low-pass, the frame stack or the recurrent cells")
        b, a, state, start = self.command_parts(obs, state, episode_start, deterministic)
        if self.residual is not None:
            a, state["filter"] = self.residual[1](b, a, state.get("filter"), start)
            a = a[:, 0]
        return to_actions(a, single), state

    def command_parts(self, obs, state, episode_start, deterministic: bool = True):
        """One step of everything before the command path, on a batch ``obs`` of the policy's
        channels: (the base's command (N,) or None without a residual, the model's action (N,),
        the state with the base's, the stack's and the recurrent cells' parts advanced, the
        episode starts (N,) bool). :meth:`predict` sends the two through the residual's
        :class:`CommandShaper`; the studies that replay the path read them apart."""
        n = len(obs)
        state = dict(state) if isinstance(state, dict) else {}
        start = (np.ones(n, bool) if episode_start is None and not state
                 else np.zeros(n, bool) if episode_start is None
                 else np.asarray(episode_start, bool).reshape(-1).copy())
        b = None
        if self.residual is not None:  # the base reads the raw observation first, as in training
            base = self.residual[0]
            b, state["base"] = base.predict(obs[:, :N_OBS], state=state.get("base"),
                                            episode_start=start, deterministic=True)
            if self.observe_estimate:
                obs = np.hstack([obs, base.estimate_features(state["base"])])
        if self.norm is not None:
            obs = self.norm.normalize_obs(obs)
        if self.frame_stack > 1:
            d = obs.shape[1]
            stack = state.get("stack")
            if stack is None or stack.shape != (n, d * self.frame_stack):
                stack = np.zeros((n, d * self.frame_stack), np.float32)
            stack = np.roll(stack, -d, axis=1)
            stack[start] = 0.0
            stack[:, -d:] = obs
            state["stack"] = stack
            obs = stack
        if self.recurrent:
            a, state["lstm"] = self.model.predict(obs, state=state.get("lstm"),
                                                  episode_start=start,
                                                  deterministic=deterministic)
        else:
            a, _ = self.model.predict(obs, deterministic=deterministic)
        return b, np.asarray(a, np.float64).reshape(-1), state, start


def combine_residual(base_action, policy_action, scale: float) -> np.ndarray:
    """clip(base + scale * clip(policy, -1, 1), -1, 1) as float32 (the action's precision),
    shape (N,): the residual's sum, before the command path's low-pass and deadband
    (:class:`CommandShaper`; the shipped policies were trained on this rounding)."""
    b = np.asarray(base_action, np.float64).reshape(-1)
    a = np.clip(np.asarray(policy_action, np.float64).reshape(-1), -1.0, 1.0)
    return np.clip(b + scale * a, -1.0, 1.0).astype(np.float32)


def check_lowpass_on(value) -> str:
    """What the command low-pass filters, one of :data:`LOWPASS_ON` (else a PolicyError)."""
    if not isinstance(value, str) or value not in LOWPASS_ON:
        raise PolicyError(f"residual lowpass_on must be one of {LOWPASS_ON}, got {value!r}")
    return value


def lowpass_gain(time_constant: float, dt: float) -> float:
    """alpha of the first-order low-pass y <- y + alpha (u - y) that holds u over each control
    step dt: the exact zero-order-hold discretisation of tau dy/dt = u - y, alpha =
    1 - exp(-dt / tau); 1 (no filter) for tau = 0."""
    return 1.0 if time_constant == 0 else 1.0 - math.exp(-dt / time_constant)


class CommandShaper:
    """The residual's command path, one object for training (the residual VecEnv wrapper) and
    evaluation (:class:`SB3Policy`): c = clip(base + scale clip(policy, -1, 1), -1, 1)
    (:func:`combine_residual`), then a first-order low-pass of time constant ``lowpass`` [s]
    (:func:`lowpass_gain`), then the ``deadband``.

    The low-pass keeps the winch set-point from stepping every control step on sensor noise and
    on the residual's own chatter: with tau = 1 s it passes the 36-45 s pendulum (baseline
    aerostat, 5-15 m/s) with a phase lag of 8-10 degrees and attenuates the 2-3.7 s pitching and
    axial-spring bands 2-3.2 times (|1 + i omega tau|). The deadband (a fraction of the winch's top speed) sets every smaller command to exactly
    zero, which applies the brake: the sum of a small base command and sensor noise then holds
    the drum instead of reeling on noise. It acts on the filtered command, so a command that
    has decayed under it brakes. The filter state starts at 0 (the drum at rest) at every
    episode start.
    """

    def __init__(self, scale: float, deadband: float = 0.0, lowpass: float = 0.0,
                 dt: float = 0.2, lowpass_on: str = "sum"):
        self.scale, self.deadband = float(scale), float(deadband)
        self.lowpass, self.dt = float(lowpass), float(dt)
        self.lowpass_on = check_lowpass_on(lowpass_on)
        self.alpha = lowpass_gain(self.lowpass, self.dt)

    def _filter(self, u, filtered, start) -> np.ndarray:
        """One step of the low-pass on u (N,) from the previous state ``filtered``."""
        y = np.zeros_like(u) if filtered is None else np.array(filtered, np.float64)
        if start is not None:
            y[np.asarray(start, bool).reshape(-1)] = 0.0
        return y + self.alpha * (u - y)

    def __call__(self, base_action, policy_action, filtered=None, start=None):
        """(command (N, 1) float32, filter state (N,)) for one step of N environments;
        ``filtered`` is the previous step's state (None: every environment starts), ``start``
        (N,) bool the environments whose episode starts at this step."""
        if self.alpha == 1.0:  # no filter: the sum itself, bit for bit
            y = combine_residual(base_action, policy_action, self.scale).astype(np.float64)
            return apply_deadband(y, self.deadband)[:, None], y
        if self.lowpass_on == "base":  # the residual bypasses the filter
            y = self._filter(np.asarray(base_action, np.float64).reshape(-1), filtered, start)
            c = combine_residual(y, policy_action, self.scale).astype(np.float64)
            return apply_deadband(c, self.deadband)[:, None], y
        c = combine_residual(base_action, policy_action, self.scale).astype(np.float64)
        y = self._filter(c, filtered, start)
        return apply_deadband(y, self.deadband)[:, None], y


def apply_deadband(action, deadband: float) -> np.ndarray:
    """``action`` as float32 with every entry smaller in magnitude than ``deadband`` zero."""
    out = np.array(action, np.float64)
    out[np.abs(out) < deadband] = 0.0
    return out.astype(np.float32)


def _algorithms() -> list:
    require("stable_baselines3", "a Stable-Baselines3 policy", "train")
    from stable_baselines3 import PPO, SAC, TD3

    algos = [PPO, SAC, TD3]
    try:
        from sb3_contrib import RecurrentPPO
    except ImportError:  # sb3-contrib is optional: its models then fail to load, clearly
        return algos
    return algos + [RecurrentPPO]


def read_wrappers(path: str | Path) -> dict:
    """The wrapper metadata saved beside a model ({} when it has none): ``<stem>_wrappers.json``
    or, for the checkpoints of a run, the folder's :data:`FOLDER_WRAPPERS`."""
    meta = wrappers_path(Path(path))
    if not meta.is_file():
        meta = Path(path).with_name(FOLDER_WRAPPERS)
    if not meta.is_file():
        return {}
    try:
        data = json.loads(meta.read_text())
        unknown = sorted(set(data) - WRAPPER_KEYS)
        wrappers = clean_wrappers(data)
    except (ValueError, TypeError, AttributeError) as exc:
        raise PolicyError(f"cannot read the wrapper metadata {meta}: {exc}") from None
    if unknown:  # a newer writer's wrapper: dropping it would run a different policy
        raise PolicyError(f"the wrapper metadata {meta} has keys this version of aerostat-gym "
                          f"does not know: {unknown} (known: {sorted(WRAPPER_KEYS)}); it was "
                          "written by a newer version")
    return wrappers


def check_model_file(path: str | Path, what: str = "policy file") -> Path:
    """``path`` as the Path of a file that can be a saved Stable-Baselines3 model (a .zip
    archive), else a PolicyError naming it as ``what`` and what is wrong."""
    path = Path(path)
    if path.is_dir():
        raise PolicyError(f"{path} is a directory, not a {what}: give the model's .zip")
    if not path.is_file():
        raise PolicyError(f"{what} not found: {path}")
    if not zipfile.is_zipfile(path):
        raise PolicyError(f"{what} {path} is not a Stable-Baselines3 model (.zip archive): "
                          "corrupt or wrong file")
    return path


def _default_policy(algo) -> type:
    """The policy class an algorithm builds by default (RecurrentPPO's is its LSTM one)."""
    aliases = algo.policy_aliases
    return aliases["MlpLstmPolicy"] if "MlpLstmPolicy" in aliases else aliases["MlpPolicy"]


def saved_algorithm(path: str | Path, what: str = "policy file") -> str | None:
    """The name of the algorithm class (``"PPO"``, ``"SAC"``, ``"TD3"``, ``"RecurrentPPO"``)
    that saved the model at ``path`` (checked with :func:`check_model_file`), read from its
    policy class without building the model; None when that class cannot be read or belongs
    to none of them. A PolicyError naming the file as ``what`` when it holds no model."""
    from stable_baselines3.common.save_util import load_from_zip_file

    path = check_model_file(path, what)
    try:
        data, _, _ = load_from_zip_file(path, device="cpu")
    except Exception as exc:  # noqa: BLE001 - any unreadable archive is the same refusal
        raise PolicyError(f"cannot read the {what} {path} as a Stable-Baselines3 model: "
                          f"{type(exc).__name__}: {exc}"[:300]) from None
    if not data:
        raise PolicyError(f"{what} {path} is a .zip archive but not a Stable-Baselines3 model "
                          "(it has no model data): wrong file")
    policy = data.get("policy_class")
    if not isinstance(policy, type):
        return None
    # RecurrentPPO's policy is an actor-critic too: the most derived default names the algorithm
    bases = [(len(_default_policy(a).__mro__), a.__name__) for a in _algorithms()
             if issubclass(policy, _default_policy(a))]
    return max(bases)[1] if bases else None


def load_sb3(path: str | Path, residual_factory=None) -> SB3Policy:
    """Load a saved model (+ its ``_vecnormalize.pkl`` and ``_wrappers.json``); clear errors
    for a missing or corrupt file. ``residual_factory(spec)`` turns the saved residual block
    into (base policy, :class:`CommandShaper`), validating it (required for a residual
    model)."""
    path = check_model_file(path)
    errors = []
    algos = _algorithms()
    for Algo in algos:
        try:
            model = Algo.load(str(path), device="cpu")
            break
        except Exception as exc:  # noqa: BLE001 - try the next algorithm, report all
            errors.append(f"{Algo.__name__}: {type(exc).__name__}: {exc}"[:200])
    else:
        names = ", ".join(a.__name__ for a in algos)
        raise PolicyError(f"cannot load {path} as a {names} model: " + "; ".join(errors))
    norm = None
    stats = vecnormalize_path(path)
    if stats.is_file():
        with open(stats, "rb") as fh:
            norm = pickle.load(fh)
        norm.training = False
    else:
        warnings.warn(f"no VecNormalize statistics beside {path} (looked for {stats.name}): the "
                      "policy sees raw observations, which is wrong if it was trained with "
                      "normalisation", stacklevel=2)
    wrappers = read_wrappers(path)
    k = wrappers.get("frame_stack", 1)
    shape = model.observation_space.shape
    if len(shape) != 1 or shape[0] % k or shape[0] // k < N_OBS:
        stacked = f" ({k} stacked frames)" if k > 1 else ""
        raise PolicyError(f"{path} was trained on observations of shape {shape}{stacked}; "
                          f"TetheredAerostat-v0 gives ({N_OBS},) (standard) or the full layout")
    residual = None
    if "residual" in wrappers:
        spec = wrappers["residual"]
        if residual_factory is None:
            raise PolicyError(f"{path} is a residual policy on {spec.get('base')!r}: load it "
                              "with load_policy, which builds the base policy")
        residual = residual_factory(spec)
    return SB3Policy(model, norm, frame_stack=k, residual=residual,
                     observe_estimate=wrappers.get("residual", {}).get("observe_estimate", False))
