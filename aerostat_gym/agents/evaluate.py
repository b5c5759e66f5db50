"""``aerostat-gym evaluate``: one evaluator for the baselines and SB3 policies on frozen suites.

Scenarios (:data:`SCENARIOS`; the along-wind swing, cross-wind displacement and pitch kick are
fixed, not drawn: a rigid rotation of aerostat and tether about the winch, then a pitch about
the confluence point, :func:`aerostat_gym.envs.episodes._perturb`):

- ``recover``: steady wind (no turbulence), the aerostat and tether swung 10 m along the wind
  and the aerostat pitched 0.05 rad, 180 s: damping ratios and periods of the longitudinal
  pendulum and the pitch oscillation identified by fitting damped sinusoids.
- ``recover_small``: as ``recover`` at a tenth of the amplitude (1 m, 0.005 rad): the linear
  regime, where the brake's dead band and the winch's speed limit matter most.
- ``recover_cross`` / ``recover_cross_small``: 10 m / 1 m across the wind (+y) and 0.05 /
  0.005 rad of pitch: the lateral pendulum, fitted on the cross-wind displacement.
- ``recover_combined`` / ``recover_combined_small``: 10 m / 1 m at 45 degrees (7.07 m along and
  7.07 m across; 0.707 m and 0.707 m) and 0.05 / 0.005 rad: both pendulums, each fitted on its
  own displacement (along-wind: longitudinal; cross-wind: lateral).
- ``gusty_light``, ``gusty`` (moderate) and ``gusty_severe``: the turbulence class's von Karman
  field (sigma_u / U(h) = 5 %, 10 %, 15 % at the aerostat), no initial perturbation, 120 s: RMS
  displacement, pitch and pitch rate, tension, length wander, winch energy.

The recover scenarios' displacements are stated for the baseline's 300 m tether
(:data:`~aerostat_gym.envs.spaces.REFERENCE_TETHER_LENGTH`, as the environment's
perturbation presets are); on another tether they scale with its length, so that every
aerostat is swung through the same angle (1.9 degrees for the 10 m swing), and the reports say
so in each scenario's description.

Suites (:data:`SUITES`) fix the wind speeds and seeds, so a number in a report can be
reproduced exactly. ``damping``, ``tiny``, ``small`` and ``full`` run without sensor noise, so
in the recover scenarios every seed is the same episode. ``report`` (the frozen protocol of
the README's baseline table) runs every scenario above at seeds 5000-5019 with the sensor noise
:data:`SENSOR_NOISE` on (:data:`SUITE_OBS_NOISE`), so the seeds of a cell differ and their
intervals mean something; ``report-tiny`` is a two-seed cut of it for tests. The report seeds
are disjoint from the training seeds (the SB3 VecEnv seeds environment i of ``aerostat-gym
train --seed S`` with S + i: 1-32 for the shipped policy, 0-35 over training seeds 0-4), from
the other suites (0, 100-109) and from the task-returns table (1000-1019). ``validation``
runs the same scenarios with the same noise at other wind speeds (recover 7.5 and 12.5 m/s,
gusty 6, 10 and 14 m/s) and seeds 7000-7009: the suite on which a training seed or checkpoint
is chosen (:mod:`aerostat_gym.agents.selection`), so the report suite stays unseen by the
choice.

The suite score is the mean episode return under the environment's default reward.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..envs.batch import held_wind_top
from ..envs.config import DEFAULT_WIND_RANGE, check_control_step
from ..envs.spaces import REFERENCE_TETHER_LENGTH, displacement_scale
from ..envs.vector import TetheredAerostatVectorEnv
from ..params import MAX_WIND_SPEED, Params, as_params, dumps_toml
from ..physics.state import S_Q, S_THETA, S_X, S_Y
from .fit_guides import guide_kwargs, guides_for, screen_fits
from .metrics import response_metrics
from .policies import load_policy
from .sb3io import policy_obs

#: Sensor noise of the report suites (std in the observation's scaled units, on every standard
#: channel): the level the LQG baseline is designed for and evaluated at in the README's
#: tables. It reaches the policies that read the standard channels
#: (passive ignores them; tension feedback, LQG and learned policies do); the privileged LQR
#: and modal controllers read the appended full state, which carries no noise.
SENSOR_NOISE = 0.01


def _recover(along: float, lateral: float, pitch: float) -> dict:
    return {"turbulence": "none",
            "perturbation": {"swing": along, "lateral": lateral, "pitch": pitch, "fixed": True}}


def _describe_start(pert: dict) -> str:
    """'calm, 10 m along-wind swing + 0.05 rad pitch' and the like."""
    along, lateral = pert["swing"], pert["lateral"]
    swing = (f"{along:.3g} m along + {lateral:.3g} m across" if along and lateral else
             f"{lateral:.3g} m cross-wind swing" if lateral else f"{along:.3g} m along-wind swing")
    return f"calm, {swing} + {pert['pitch']:g} rad pitch"


@dataclass(frozen=True)
class Scenario:
    """One evaluation scenario: environment keyword arguments (for a tether of
    :data:`REFERENCE_TETHER_LENGTH`), duration [s], a one-line description (of a forced
    response; a free response's is written from its start) and, for a free response, the
    displacements its pendulum fits use ("x": along-wind, longitudinal pendulum; "y":
    cross-wind, lateral pendulum; empty for a forced response, which gets no damping fits)."""

    env_kwargs: dict
    duration: float
    description: str = ""
    pendulums: tuple = ()

    @property
    def free(self) -> bool:
        return bool(self.pendulums)

    def env_kwargs_for(self, tether_length: float | None = None,
                       scale: float | None = None) -> dict:
        """The environment keyword arguments on a tether of ``tether_length`` [m] (None: the
        reference): a free response's swing and cross-wind displacement times ``scale``
        (default :func:`displacement_scale` of the tether)."""
        if not self.free:
            return dict(self.env_kwargs)
        pert = self.env_kwargs["perturbation"]
        k = displacement_scale(tether_length) if scale is None else float(scale)
        return {**self.env_kwargs,
                "perturbation": {**pert, "swing": pert["swing"] * k, "lateral": pert["lateral"] * k}}

    def describe(self, tether_length: float | None = None) -> str:
        """The one-line description on a tether of ``tether_length`` [m] (None: the
        reference), naming the scaling where there is one."""
        if not self.free:
            return self.description
        text = _describe_start(self.env_kwargs_for(tether_length)["perturbation"])
        k = displacement_scale(tether_length)
        if k != 1.0:
            text += (f" (the {REFERENCE_TETHER_LENGTH:g} m reference's displacements x {k:.3g} "
                     f"for the {tether_length:g} m tether)")
        return text


_D = 10.0 / math.sqrt(2.0)  # 7.07 m: a 10 m swing at 45 degrees
SCENARIOS = {
    "recover": Scenario(_recover(10.0, 0.0, 0.05), 180.0, pendulums=("x",)),
    "recover_small": Scenario(_recover(1.0, 0.0, 0.005), 180.0, pendulums=("x",)),
    "recover_cross": Scenario(_recover(0.0, 10.0, 0.05), 180.0, pendulums=("y",)),
    "recover_cross_small": Scenario(_recover(0.0, 1.0, 0.005), 180.0, pendulums=("y",)),
    "recover_combined": Scenario(_recover(_D, _D, 0.05), 180.0, pendulums=("x", "y")),
    "recover_combined_small": Scenario(_recover(_D / 10, _D / 10, 0.005), 180.0,
                                       pendulums=("x", "y")),
    "gusty_light": Scenario({"turbulence": "light", "perturbation": "none"}, 120.0,
                            "light turbulence (sigma_u/U = 5 %), no perturbation"),
    "gusty": Scenario({"turbulence": "moderate", "perturbation": "none"}, 120.0,
                      "moderate turbulence (sigma_u/U = 10 %), no perturbation"),
    "gusty_severe": Scenario({"turbulence": "severe", "perturbation": "none"}, 120.0,
                             "severe turbulence (sigma_u/U = 15 %), no perturbation"),
}
RECOVER = SCENARIOS["recover"].env_kwargs
GUSTY = SCENARIOS["gusty"].env_kwargs

#: Seeds of the report suite: disjoint from training (1-32 for the shipped policy), the other
#: suites (0, 100-109) and the task-returns table (1000-1019).
REPORT_SEEDS = list(range(5000, 5020))
REPORT_RECOVER_SPEEDS = [5.0, 10.0, 15.0]
#: 16 m/s lies outside the training range DEFAULT_WIND_RANGE = (3, 15).
REPORT_GUSTY_SPEEDS = [4.0, 8.0, 12.0, 16.0]
#: The validation suite, for choosing among trained policies (training seeds, checkpoints)
#: without looking at the report suite: the report's scenarios at wind speeds between the
#: report's (inside the training range) and seeds disjoint from every other suite, so a policy
#: chosen on it is then judged on cases its choice never saw.
VALIDATION_SEEDS = list(range(7000, 7010))
VALIDATION_RECOVER_SPEEDS = [7.5, 12.5]
VALIDATION_GUSTY_SPEEDS = [6.0, 10.0, 14.0]
RECOVER_SCENARIOS = [k for k, s in SCENARIOS.items() if s.free]
GUSTY_SCENARIOS = [k for k, s in SCENARIOS.items() if not s.free]

SUITES = {
    "damping": {"recover": ([5.0, 10.0, 15.0], [0])},  # model selection during training
    "tiny": {"recover": ([5.0, 10.0, 15.0], [0]), "gusty": ([10.0], [100, 101])},
    "small": {"recover": ([5.0, 10.0, 15.0], [0]), "gusty": ([5.0, 10.0, 15.0], [100, 101, 102])},
    "full": {"recover": ([3.0, 5.0, 7.5, 10.0, 12.5, 15.0], [0]),
             "gusty": ([5.0, 10.0, 15.0], list(range(100, 110)))},
    "report": {**{k: (REPORT_RECOVER_SPEEDS, REPORT_SEEDS) for k in RECOVER_SCENARIOS},
               **{k: (REPORT_GUSTY_SPEEDS, REPORT_SEEDS) for k in GUSTY_SCENARIOS}},
    "validation": {
        **{k: (VALIDATION_RECOVER_SPEEDS, VALIDATION_SEEDS) for k in RECOVER_SCENARIOS},
        **{k: (VALIDATION_GUSTY_SPEEDS, VALIDATION_SEEDS) for k in GUSTY_SCENARIOS}},
    "report-tiny": {"recover_cross_small": ([10.0], REPORT_SEEDS[:2]),
                    "gusty_severe": ([16.0], REPORT_SEEDS[:2])},
}
#: Sensor noise per suite (0 where absent).
SUITE_OBS_NOISE = {"report": SENSOR_NOISE, "report-tiny": SENSOR_NOISE,
                   "validation": SENSOR_NOISE}


def suite_seeds(name: str) -> set:
    """Every seed a suite uses."""
    return {s for _, seeds in check_suite(name).values() for s in seeds}


def suite_cells(name: str, speeds=None) -> dict:
    """A suite's cells ({scenario: (speeds, seeds)}); with ``speeds`` (mean wind speeds [m/s],
    finite, in [0, MAX_WIND_SPEED], no repeats) every scenario runs at those speeds instead, on
    the suite's own seeds, sensor noise and durations: the suite's scenarios at the winds of
    your site."""
    cells = check_suite(name)
    if speeds is None:
        return cells
    try:
        us = sorted(float(u) for u in speeds)
    except (TypeError, ValueError):
        raise ValueError(f"speeds must be numbers [m/s], got {speeds!r}") from None
    if not us or not all(math.isfinite(u) and 0.0 <= u <= MAX_WIND_SPEED for u in us) \
            or len(set(us)) != len(us):
        raise ValueError(f"speeds must be finite wind speeds in [0, {MAX_WIND_SPEED:g}] m/s "
                         f"without repeats, got {list(speeds)!r}")
    return {sc: (us, seeds) for sc, (_, seeds) in cells.items()}


def cells_wind_range(cells: dict, params=None) -> tuple[float, float]:
    """The training range DEFAULT_WIND_RANGE widened to every speed of ``cells``: the range the
    environments run in and the baselines are scheduled over. With ``params``, the training
    range's top comes down to the highest wind whose trim the configured tether holds
    (:func:`default_wind_range`), so an aerostat that cannot fly at 15 m/s runs cells at the
    winds it can."""
    us = [u for speeds, _ in cells.values() for u in speeds]
    lo, hi = DEFAULT_WIND_RANGE if params is None else default_wind_range(params)
    return min(lo, min(us)), max(hi, max(us))


def default_wind_range(params=None) -> tuple[float, float]:
    """DEFAULT_WIND_RANGE, its top lowered to the highest wind whose trim the tether of
    ``params`` (a Params, a file or a shipped name; None: the baseline, which holds it all)
    holds (:func:`~aerostat_gym.envs.batch.held_wind_top`)."""
    lo, hi = DEFAULT_WIND_RANGE
    if params is None:
        return lo, hi
    params = as_params(params)
    return lo, held_wind_top(params, lo, hi)


def held_suite_speeds(name: str, params=None) -> list | None:
    """Wind speeds to run suite ``name`` at on an aerostat whose tether cannot hold all of its
    own (its speeds up to the highest held wind, or that wind alone: :func:`suite_cells`'s
    ``speeds``), or None where it holds them all (the suite runs as it is)."""
    us = sorted({u for speeds, _ in check_suite(name).values() for u in speeds})
    if params is None:
        return None
    params = as_params(params)
    top = held_wind_top(params, min(us), max(us))
    if top >= max(us):
        return None
    return [u for u in us if u <= top] or [top]


def tether_length_of(params) -> float | None:
    """The tether length [m] of ``params`` (a Params, a TOML path or a shipped configuration's
    name), None for the baseline (None)."""
    return None if params is None else as_params(params).tether.length


def describe_suite(name: str, speeds=None, tether_length: float | None = None) -> str:
    """One line per scenario of a suite (at ``speeds`` if given, see :func:`suite_cells`): wind
    speeds, seeds (as ranges) and description (on a tether of ``tether_length`` [m], None: the
    reference)."""
    lines = []
    for scenario, (us, seeds) in suite_cells(name, speeds).items():
        s = sorted(seeds)
        span = (f"{s[0]}-{s[-1]}" if len(s) > 2 and s == list(range(s[0], s[-1] + 1))
                else ", ".join(map(str, s)))
        lines.append(f"- `{scenario}` ({SCENARIOS[scenario].describe(tether_length)}, "
                     f"{SCENARIOS[scenario].duration:g} s): U = "
                     f"{', '.join(f'{u:g}' for u in us)} m/s; seeds {span}")
    noise = SUITE_OBS_NOISE.get(name, 0.0)
    lines.append(f"- sensor noise obs_noise = {noise:g} (scaled units)")
    return "\n".join(lines)


@dataclass
class Episodes:
    """Time histories of one scenario for one policy (arrays: episode x sample; NaN after a
    termination)."""

    scenario: str
    speeds: np.ndarray
    seeds: np.ndarray
    time: np.ndarray
    x: np.ndarray  # along-wind CM displacement from trim [m]
    pitch: np.ndarray  # pitch minus trim [rad]
    tension: np.ndarray  # winch tension [N] (noise-free, whatever the sensor noise)
    reel_speed: np.ndarray  # [m/s]
    returns: np.ndarray
    ended: list  # termination reason or None per episode
    y: np.ndarray | None = None  # cross-wind CM displacement from trim [m]
    pitch_rate: np.ndarray | None = None  # body rate q [rad/s]
    length: np.ndarray | None = None  # paid-out tether length minus trim [m]
    params: Params | None = None  # the aerostat the episodes ran on (None: the baseline)


def check_suite(name: str) -> dict:
    if name not in SUITES:
        raise ValueError(f"unknown suite {name!r}; choose one of {list(SUITES)}")
    return SUITES[name]


def run_scenario(policy, scenario: str, speeds, seeds, control_step: float = 0.2,
                 env_kwargs: dict | None = None, displacement_scale: float | None = None
                 ) -> Episodes:
    """Run ``policy`` on every (speed, seed) pair of a scenario in one batched environment.

    A free response's displacements are the reference tether's times the tether's
    :func:`displacement_scale`, or times ``displacement_scale`` where given (1.0: the stated
    metres on any tether).

    The environment's wind-speed range is the training range DEFAULT_WIND_RANGE widened to
    the requested speeds (so the suites inside it run on exactly the training environment's
    trims and turbulence bank). The tension is the winch tension of the state, not the load-cell
    channel: with ``obs_noise`` the policy sees a noisy load cell, the metrics do not, and they
    are not clipped to the observation's bounds either.
    """
    sc = SCENARIOS[scenario]
    pairs = [(u, s) for u in speeds for s in seeds]
    steps = int(round(sc.duration / check_control_step(control_step)))
    params = (env_kwargs or {}).get("params")
    kwargs = {"wind_speed": cells_wind_range({scenario: (speeds, seeds)}, params),
              **(env_kwargs or {}),
              **sc.env_kwargs_for(tether_length_of(params), displacement_scale)}
    env = TetheredAerostatVectorEnv(num_envs=len(pairs), max_episode_steps=steps,
                                    observation="full", control_step=control_step, **kwargs)
    obs, _ = env.reset(seed=[s for _, s in pairs],
                       options={"wind_speed": [u for u, _ in pairs]})
    b, lay = env.batch, env.batch.layout
    ix, iy, ith = lay.at(S_X), lay.at(S_Y), lay.at(S_THETA)
    iq, iv, il = lay.at(S_Q), lay.winch_speed, lay.winch_length
    names = ("x", "y", "pitch", "q", "length", "tension", "reel")
    rec = {k: np.zeros((len(pairs), steps + 1)) for k in names}

    def record(k, obs, alive):
        d = b.state - b.trim_state
        for name, col in (("x", ix), ("y", iy), ("pitch", ith), ("length", il)):
            rec[name][:, k] = np.where(alive, d[:, col], np.nan)
        rec["q"][:, k] = np.where(alive, b.state[:, iq], np.nan)
        rec["reel"][:, k] = np.where(alive, b.state[:, iv], np.nan)
        rec["tension"][:, k] = np.where(alive, b.winch_tensions(), np.nan)

    returns, ended = rollout(policy, env, obs, steps, record)
    env.close()
    t = np.arange(steps + 1) * control_step
    return Episodes(scenario, np.array([u for u, _ in pairs]), np.array([s for _, s in pairs]),
                    t, rec["x"], rec["pitch"], rec["tension"], rec["reel"], returns, ended,
                    y=rec["y"], pitch_rate=rec["q"], length=rec["length"], params=b.params)


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


def episode_metrics(ep: Episodes, i: int) -> dict:
    """Per-episode metrics (:func:`aerostat_gym.agents.metrics.response_metrics`) with the
    wind speed, seed, return, termination reason (``ended``) and ``terminated`` (1.0 or 0.0).
    The lateral pendulum is fitted only in scenarios that swing across the wind. On an
    aerostat other than the baseline the fits start from its linear modes and the fits the
    record cannot support read NaN (:func:`aerostat_gym.agents.fit_guides.screen_fits`)."""
    sc = SCENARIOS.get(ep.scenario)
    lateral = sc is not None and "y" in sc.pendulums

    def row(a):
        return None if a is None else a[i]

    guides = guides_for(ep.params, float(ep.speeds[i]))
    m = screen_fits(response_metrics(ep.time, ep.x[i], ep.pitch[i], ep.tension[i],
                                     ep.reel_speed[i], y_disp=row(ep.y),
                                     pitch_rate=row(ep.pitch_rate), length_dev=row(ep.length),
                                     fit_lateral=lateral, **guide_kwargs(guides)),
                    guides, float(ep.time[-1] - ep.time[0]))
    m.update({"wind_speed": float(ep.speeds[i]), "seed": int(ep.seeds[i]),
              "return": float(ep.returns[i]), "ended": ep.ended[i],
              "terminated": float(ep.ended[i] is not None)})
    return m


def suite_episodes(policy, suite: str, control_step: float = 0.2, params=None, speeds=None):
    """(scenario, :class:`Episodes`) for every scenario of a suite (at ``speeds`` if given,
    see :func:`suite_cells`), each run in one batch in the environment of ``params`` (a
    Params; None: the baseline) with the suite's sensor noise: the one loop behind
    :func:`evaluate_policy`, :func:`suite_result` and :func:`suite_score`."""
    yield from cells_episodes(policy, suite_cells(suite, speeds),
                              SUITE_OBS_NOISE.get(suite, 0.0), control_step, params)


def cells_episodes(policy, cells: dict, obs_noise: float, control_step: float = 0.2,
                   params=None):
    """(scenario, :class:`Episodes`) for every scenario of ``cells`` ({scenario: (speeds,
    seeds)}, the form of :data:`SUITES`' entries), each run in one batch with sensor noise
    ``obs_noise`` in the environment of ``params`` (None: the baseline)."""
    kwargs = {"obs_noise": obs_noise}
    if params is not None:
        kwargs["params"] = params
    for scenario, (speeds, seeds) in cells.items():
        yield scenario, run_scenario(policy, scenario, speeds, seeds, control_step,
                                     env_kwargs=kwargs)


def warn_still_air(policy_name: str, cells: dict) -> None:
    """Warn where ``cells`` run a policy other than the braked winch at U = 0, where it reads
    as the braked winch."""
    if policy_name != "passive" and any(u == 0 for sp, _ in cells.values() for u in sp):
        warnings.warn(f"{policy_name} at U = 0 m/s: in still air the tether hangs vertical and "
                      "reeling moves the aerostat along it, so the winch has no linear authority "
                      "over the pendulum; the scheduled controllers fade to the braked winch "
                      "there (agents.scheduling.low_wind_fade) and read as passive", UserWarning,
                      stacklevel=3)


def evaluate_policy(policy_name: str, suite: str = "tiny", control_step: float = 0.2,
                    params=None, speeds=None) -> dict:
    """Metrics of one policy on a suite: {scenario: [per-episode metrics]}, plus the score.

    ``params`` (a Params, a TOML path, a shipped configuration's name or None for the baseline)
    is the configuration of both the baselines' design and the environment the suite runs on;
    the resolved parameters are recorded in the result (``params_toml``). The suite's sensor
    noise (:data:`SUITE_OBS_NOISE`) is on in its environments and the LQG filter is designed
    for it. With ``speeds`` every scenario runs at those wind speeds (:func:`suite_cells`), the
    baselines scheduled over the range that covers them; the result records them (``speeds``).
    """
    cells = suite_cells(suite, speeds)
    noise = SUITE_OBS_NOISE.get(suite, 0.0)
    params = as_params(params)
    warn_still_air(policy_name, cells)
    policy = load_policy(policy_name, params=params, dt=control_step, obs_noise=noise,
                         wind_range=default_wind_range(params) if speeds is None
                         else cells_wind_range(cells, params))
    out = {"policy": policy_name, "suite": suite, "scenarios": {}, "obs_noise": noise,
           "speeds": None if speeds is None else cells[next(iter(cells))][0],
           "tether_length_m": params.tether.length, "params_toml": dumps_toml(params)}
    returns = []
    for scenario, ep in suite_episodes(policy, suite, control_step, params, speeds):
        rows = [episode_metrics(ep, i) for i in range(len(ep.speeds))]
        if hasattr(policy, "predicted_modes"):
            for r in rows:
                r["predicted"] = policy.predicted_modes(r["wind_speed"])
        out["scenarios"][scenario] = {"episodes": rows, "histories": ep}
        returns.extend(ep.returns.tolist())
    out["score"] = float(np.mean(returns))
    return out


def suite_result(policy, label: str, suite: str = "report", params=None) -> dict:
    """A policy object's episodes on every cell of a suite, with the suite's sensor noise, as an
    evaluation result without the histories (what :func:`aerostat_gym.agents.protocol.aggregate`
    reads): for policies that have no name, such as a design of the authority sweep or a
    baseline wrapped in a deadband."""
    return cells_result(policy, label, check_suite(suite), SUITE_OBS_NOISE.get(suite, 0.0),
                        params, suite=suite)


def cells_result(policy, label: str, cells: dict, obs_noise: float, params=None,
                 suite: str = "custom") -> dict:
    """:func:`suite_result` on any cells ({scenario: (speeds, seeds)}) at sensor noise
    ``obs_noise``: the same result format, for studies that run the suites' scenarios at other
    wind speeds or seeds."""
    scenarios = {sc: {"episodes": [episode_metrics(ep, i) for i in range(len(ep.speeds))]}
                 for sc, ep in cells_episodes(policy, cells, obs_noise, params=params)}
    return {"policy": label, "label": label, "suite": suite, "obs_noise": float(obs_noise),
            "scenarios": scenarios}


def suite_score(policy, suite: str = "tiny", control_step: float = 0.2, params=None,
                speeds=None) -> float:
    """Mean episode return of a policy object on a suite (the training curve's measure), in
    the environment of ``params`` (default: the baseline) with the suite's sensor noise, at
    ``speeds`` if given (:func:`suite_cells`)."""
    returns = [r for _, ep in suite_episodes(policy, suite, control_step, params, speeds)
               for r in ep.returns]
    return float(np.mean(returns))
