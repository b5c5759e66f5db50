"""``aerostat-gym evaluate``: one evaluator for the baselines and SB3 policies on frozen suites.

Scenarios:

- ``recover``: steady wind (no turbulence), the aerostat and tether swung 10 m along the wind
  and the aerostat pitched 0.05 rad (fixed, not drawn), 180 s: damping ratios and periods of
  the longitudinal pendulum and the pitch oscillation identified by fitting damped sinusoids.
- ``gusty``: moderate turbulence (von Karman, sigma_u = 1.6 m/s), no initial perturbation,
  120 s: RMS displacement and pitch, tension, winch energy.

Suites fix the wind speeds and seeds (``SUITES``), so a number in a report can be reproduced
exactly. The suite score is the mean episode return under the environment's default reward.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..envs.config import DEFAULT_WIND_RANGE
from ..envs.spaces import CHANNELS, N_OBS, OBS_TENSION
from ..envs.vector import TetheredAerostatVectorEnv
from ..params import dumps_toml, load_params
from .metrics import response_metrics
from .policies import load_policy
from .sb3io import PolicyError

RECOVER = {"turbulence": "none",
           "perturbation": {"swing": 10.0, "pitch": 0.05, "fixed": True}}
GUSTY = {"turbulence": "moderate", "perturbation": "none"}
SCENARIOS = {"recover": (RECOVER, 180.0), "gusty": (GUSTY, 120.0)}
SUITES = {
    "damping": {"recover": ([5.0, 10.0, 15.0], [0])},  # model selection during training
    "tiny": {"recover": ([5.0, 10.0, 15.0], [0]), "gusty": ([10.0], [100, 101])},
    "small": {"recover": ([5.0, 10.0, 15.0], [0]), "gusty": ([5.0, 10.0, 15.0], [100, 101, 102])},
    "full": {"recover": ([3.0, 5.0, 7.5, 10.0, 12.5, 15.0], [0]),
             "gusty": ([5.0, 10.0, 15.0], list(range(100, 110)))},
}


@dataclass
class Episodes:
    """Time histories of one scenario for one policy (arrays: episode x sample)."""

    scenario: str
    speeds: np.ndarray
    seeds: np.ndarray
    time: np.ndarray
    x: np.ndarray  # along-wind CM displacement from trim [m]
    pitch: np.ndarray  # pitch minus trim [rad]
    tension: np.ndarray  # winch tension [N]
    reel_speed: np.ndarray  # [m/s]
    returns: np.ndarray
    ended: list  # termination reason or None per episode


def check_suite(name: str) -> dict:
    if name not in SUITES:
        raise ValueError(f"unknown suite {name!r}; choose one of {list(SUITES)}")
    return SUITES[name]


def run_scenario(policy, scenario: str, speeds, seeds, control_step: float = 0.2,
                 env_kwargs: dict | None = None) -> Episodes:
    """Run ``policy`` on every (speed, seed) pair of a scenario in one batched environment."""
    kwargs, duration = SCENARIOS[scenario]
    pairs = [(u, s) for u in speeds for s in seeds]
    steps = int(round(duration / control_step))
    env = TetheredAerostatVectorEnv(num_envs=len(pairs), max_episode_steps=steps,
                                    observation="full", control_step=control_step,
                                    **{**(env_kwargs or {}), **kwargs})
    obs, _ = env.reset(seed=[s for _, s in pairs],
                       options={"wind_speed": [u for u, _ in pairs]})
    b, lay = env.batch, env.batch.layout
    ix, ith, iv = lay.cm_pos.start, lay.euler.start + 1, lay.winch_speed
    rec = {k: np.zeros((len(pairs), steps + 1)) for k in ("x", "pitch", "tension", "reel")}

    def record(k, obs, alive):
        rec["x"][:, k] = np.where(alive, b.state[:, ix] - b.trim_state[:, ix], np.nan)
        rec["pitch"][:, k] = np.where(alive, b.state[:, ith] - b.trim_state[:, ith], np.nan)
        rec["tension"][:, k] = np.where(alive, obs[:, OBS_TENSION] * CHANNELS[OBS_TENSION].scale,
                                        np.nan)
        rec["reel"][:, k] = np.where(alive, b.state[:, iv], np.nan)

    returns, ended = rollout(policy, env, obs, steps, record)
    env.close()
    t = np.arange(steps + 1) * control_step
    return Episodes(scenario, np.array([u for u, _ in pairs]), np.array([s for _, s in pairs]),
                    t, rec["x"], rec["pitch"], rec["tension"], rec["reel"], returns, ended)


def rollout(policy, env, obs: np.ndarray, steps: int, record=None) -> tuple[np.ndarray, list]:
    """Run ``policy`` deterministically for ``steps`` steps on a vector env just reset to
    ``obs``; returns (episode return per environment, termination reason or None). Rewards
    count until an environment terminates; ``record(k, obs, alive)`` is called after the reset
    (k = 0) and after every step."""
    n = obs.shape[0]
    alive, ended, returns = np.ones(n, bool), [None] * n, np.zeros(n)
    state, start = None, np.ones(n, bool)
    if record is not None:
        record(0, obs, alive)
    for k in range(1, steps + 1):
        action, state = policy.predict(policy_obs(policy, obs), state=state, episode_start=start,
                                       deterministic=True)
        start[:] = False
        obs, rew, term, _, info = env.step(np.asarray(action, np.float32).reshape(-1, 1))
        returns += np.where(alive, rew, 0.0)
        for i in np.flatnonzero(term & alive):
            ended[i] = info["termination"][i]
        alive &= ~term
        if record is not None:
            record(k, obs, alive)
    return returns, ended


def policy_obs(policy, obs: np.ndarray) -> np.ndarray:
    """The observation slice a policy reads: the standard channels or the privileged full set."""
    need = getattr(policy, "obs_dim", None)
    if need is None or need == obs.shape[1]:
        return obs
    if need == N_OBS:
        return obs[:, :N_OBS]
    raise PolicyError(f"the policy expects observations of {need} channels; the environment "
                      f"gives {N_OBS} (observation='standard') or {obs.shape[1]} ('full'): it was "
                      "trained for another observation layout")


def episode_metrics(ep: Episodes, i: int) -> dict:
    m = response_metrics(ep.time, ep.x[i], ep.pitch[i], ep.tension[i], ep.reel_speed[i])
    m.update({"wind_speed": float(ep.speeds[i]), "seed": int(ep.seeds[i]),
              "return": float(ep.returns[i]), "ended": ep.ended[i]})
    return m


def evaluate_policy(policy_name: str, suite: str = "tiny", control_step: float = 0.2,
                    params=None) -> dict:
    """Metrics of one policy on a suite: {scenario: [per-episode metrics]}, plus the score.

    ``params`` (a Params, a TOML path, a shipped configuration's name or None for the baseline)
    is the configuration of both the baselines' design and the environment the suite runs on;
    the resolved parameters are recorded in the result (``params_toml``).
    """
    spec = check_suite(suite)
    params = params if params is not None and not isinstance(params, str) else load_params(params)
    policy = load_policy(policy_name, params=params, dt=control_step,
                         wind_range=DEFAULT_WIND_RANGE)
    out = {"policy": policy_name, "suite": suite, "scenarios": {},
           "tether_length_m": params.tether.length, "params_toml": dumps_toml(params)}
    returns = []
    for scenario, (speeds, seeds) in spec.items():
        ep = run_scenario(policy, scenario, speeds, seeds, control_step,
                          env_kwargs={"params": params})
        rows = [episode_metrics(ep, i) for i in range(len(ep.speeds))]
        if hasattr(policy, "predicted_modes"):
            for r in rows:
                r["predicted"] = policy.predicted_modes(r["wind_speed"])
        out["scenarios"][scenario] = {"episodes": rows, "histories": ep}
        returns.extend(ep.returns.tolist())
    out["score"] = float(np.mean(returns))
    return out


def suite_score(policy, suite: str = "tiny", control_step: float = 0.2, params=None) -> float:
    """Mean episode return of a policy object on a suite (the training curve's measure), in
    the environment of ``params`` (default: the baseline)."""
    returns = []
    kwargs = None if params is None else {"params": params}
    for scenario, (speeds, seeds) in check_suite(suite).items():
        returns.extend(run_scenario(policy, scenario, speeds, seeds, control_step,
                                    env_kwargs=kwargs).returns)
    return float(np.mean(returns))
