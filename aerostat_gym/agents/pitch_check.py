"""What the protocol's pitch damping ratio measures: its fit applied where the modes are known.

The pitch history of a recover scenario carries, besides the slow pendulum, the pitching mode
and the axial-spring mode, whose periods lie close together (2.0-2.8 s and 3.0-3.7 s on the
baseline at 5-15 m/s). The protocol fits the pendulum and one fast damped sinusoid
(:func:`aerostat_gym.agents.metrics.response_metrics`), so its "pitch damping ratio" is the decay
of that blend. :func:`linear_pitch_check` applies the same fit to the linear braked response
from the scenario's own start, whose modes are the eigenvalues of the linearization, and to the
nonlinear braked run from the same start: the two fits agree where the start is small (the
simulator is the linearization there), and both differ from the pitching mode's damping ratio
by the blend. The same function applies the three-mode fit of
:mod:`aerostat_gym.agents.metrics_modes` to the linear response, started away from the modes,
and it returns the pitching mode; :func:`pitching_mode_study` then measures the pitching mode's
damping of each policy's nonlinear runs with it. :func:`pitch_fit_coverage` counts, on any
aerostat, how many of the evaluator's pitch fits catch one of its fast modes at all
(:mod:`aerostat_gym.agents.fit_guides`).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..analysis.linear import propagate
from ..analysis.modes import analyse
from ..analysis.trim import find_equilibrium
from ..envs.config import DEFAULT_WIND_RANGE
from ..envs.vector import TetheredAerostatVectorEnv
from ..params import as_params
from ..physics.state import S_THETA, S_X
from .evaluate import (
    RECOVER_SCENARIOS,
    SCENARIOS,
    SENSOR_NOISE,
    cells_episodes,
    cells_wind_range,
    episode_metrics,
    run_scenario,
    tether_length_of,
)
from .fit_guides import FAST_MODE_FACTOR, fit_guides, is_baseline
from .metrics import _failed, fit_damped_sinusoid, response_metrics
from .metrics_modes import fit_modes, nearest_mode
from .policies import PassivePolicy, load_policy
from .protocol_stats import paired_difference_ci

#: Longitudinal modes whose damping ratio is reported beside the fit.
REPORTED_MODES = ("pitching", "axial spring")
#: Start of the fast modes away from the linear ones, to show that the fit does not return its
#: start: (damping-ratio factor, pitching-period factor, axial-spring-period factor).
AWAY_START = (0.5, 1.1, 0.9)


def scenario_start(params, wind_speed: float, scenario: str) -> np.ndarray:
    """The scenario's start as a deviation from trim (the environment's full layout)."""
    env = TetheredAerostatVectorEnv(1, wind_speed=(wind_speed, wind_speed), params=params,
                                    **SCENARIOS[scenario].env_kwargs_for(tether_length_of(params)))
    env.reset(seed=[0], options={"wind_speed": [wind_speed]})
    dx0 = env.batch.state[0] - env.batch.trim_state[0]
    env.close()
    return dx0


def linear_pitch_check(params, wind_speed: float, scenario: str = "recover",
                       dt: float = 0.2) -> dict:
    """The protocol's pitch fit on the linear and on the nonlinear braked response of a
    scenario's start, beside the linear pitching and axial-spring modes (periods [s], damping
    ratios)."""
    if not SCENARIOS[scenario].free:
        raise ValueError(f"scenario {scenario!r} is not a free response (a recover scenario)")
    modal = analyse(params, find_equilibrium(params, float(wind_speed)))
    lin, lay = modal.linear, modal.linear.layout
    mech = lay.n_mechanical
    steps = int(round(SCENARIOS[scenario].duration / dt))
    Ad = sla.expm(lin.A * dt)  # braked: the paid-out length is fixed, no set-point
    X = propagate(Ad, scenario_start(params, wind_speed, scenario)[:mech], steps)
    t = np.arange(steps + 1) * dt
    zero = np.zeros(steps + 1)
    fit = response_metrics(t, X[:, lay.at(S_X)], X[:, lay.at(S_THETA)], zero, zero)
    ep = run_scenario(PassivePolicy(), scenario, [wind_speed], [0], control_step=dt,
                      env_kwargs={"params": params})
    nonlinear = response_metrics(ep.time, ep.x[0], ep.pitch[0], ep.tension[0], ep.reel_speed[0])
    out = {"scenario": scenario, "wind_speed": float(wind_speed),
           "linear_fit_zeta": fit["pitch_zeta"], "linear_fit_period_s": fit["pitch_period_s"],
           "nonlinear_fit_zeta": nonlinear["pitch_zeta"],
           "nonlinear_fit_period_s": nonlinear["pitch_period_s"]}
    for label in REPORTED_MODES:
        mode = modal.find("long", label)
        key = label.replace(" ", "_")
        out[f"{key}_zeta"] = mode.zeta if mode else float("nan")
        out[f"{key}_period_s"] = mode.period if mode else float("nan")
    pitching = _pitching_fit(t, X[:, lay.at(S_X)], X[:, lay.at(S_THETA)], modal,
                             away=True)
    out["linear_modes_fit_zeta"], out["linear_modes_fit_period_s"] = (pitching.zeta,
                                                                       pitching.period)
    return out


def _pitching_fit(t, x, pitch, modal, away: bool = False):
    """The pitching mode of a pitch history by :func:`fit_modes` (pendulum started from the
    along-wind displacement's fit, pitching and axial spring from the linear ``modal`` analysis,
    or from :data:`AWAY_START` off them with ``away``)."""
    pend = fit_damped_sinusoid(t, x)
    pit, ax = modal.find("long", "pitching"), modal.find("long", "axial spring")
    if not (pend.ok and pit and ax):
        return _failed("no pendulum fit, or no linear pitching or axial-spring mode")
    zeta_f, pit_f, ax_f = AWAY_START if away else (1.0, 1.0, 1.0)
    fits = fit_modes(t, pitch, [(pend.zeta, pend.period),
                                (zeta_f * pit.zeta, pit_f * pit.period),
                                (zeta_f * ax.zeta, ax_f * ax.period)])
    return nearest_mode(fits[1:], pit.period)


def pitching_mode_study(params, scenario: str, wind_speed: float, seeds, policies,
                        obs_noise: float = 0.01, reference: str = "passive") -> dict:
    """The pitching mode's damping ratio (:func:`fit_modes`, the fast modes started at the
    linear ones) of each named policy's runs of a scenario, its mean and its paired difference
    from ``reference`` on the same seeds (95 % interval), beside the linear pitching mode."""
    modal = analyse(params, find_equilibrium(params, float(wind_speed)))
    zetas = {}
    for name in policies:
        policy = load_policy(name, params=params, wind_range=DEFAULT_WIND_RANGE,
                             obs_noise=obs_noise)  # as the evaluator loads it
        ep = run_scenario(policy, scenario, [wind_speed], seeds,
                          env_kwargs={"params": params, "obs_noise": obs_noise})
        zetas[name] = np.array([_pitching_fit(ep.time, ep.x[i], ep.pitch[i], modal).zeta
                                for i in range(len(seeds))])
    pit = modal.find("long", "pitching")
    rows = []
    for name, z in zetas.items():
        row = {"policy": name, "zeta": float(np.nanmean(z)), "failed_fits": int(np.isnan(z).sum())}
        both = np.isfinite(z) & np.isfinite(zetas[reference])  # seeds both fits resolved
        if name != reference and both.sum() >= 2:
            iv = paired_difference_ci(z[both], zetas[reference][both])
            row["diff"], row["ci"] = iv.estimate, [iv.low, iv.high]
        rows.append(row)
    return {"scenario": scenario, "wind_speed": float(wind_speed), "seeds": list(seeds),
            "linear_pitching_zeta": pit.zeta, "reference": reference, "rows": rows}


def check_markdown(rows: list[dict]) -> str:
    """A Markdown table of :func:`linear_pitch_check` rows."""
    head = ("| scenario | U [m/s] | linear modes: pitching | axial spring | protocol fit, linear "
            "braked response | protocol fit, nonlinear braked run | three-mode fit, linear braked "
            "response |\n|---|---|---|---|---|---|---|\n")
    return head + "".join(
        f"| `{r['scenario']}` | {r['wind_speed']:g} | {r['pitching_zeta']:.3f} "
        f"({r['pitching_period_s']:.2f} s) | {r['axial_spring_zeta']:.3f} "
        f"({r['axial_spring_period_s']:.2f} s) | {r['linear_fit_zeta']:.3f} "
        f"({r['linear_fit_period_s']:.2f} s) | {r['nonlinear_fit_zeta']:.3f} "
        f"({r['nonlinear_fit_period_s']:.2f} s) | {r['linear_modes_fit_zeta']:.3f} "
        f"({r['linear_modes_fit_period_s']:.2f} s) |\n" for r in rows)


def study_markdown(studies: list[dict]) -> str:
    """A Markdown table of :func:`pitching_mode_study` results (one row per speed and policy)."""
    lines = ["| scenario | U [m/s] | linear pitching mode | policy | pitching-mode zeta | "
             "paired difference from the reference [95 % CI] |", "|---|---|---|---|---|---|"]
    for st in studies:
        for r in st["rows"]:
            diff = (f"{r['diff']:+.4f} [{r['ci'][0]:+.4f}, {r['ci'][1]:+.4f}]" if "diff" in r
                    else "reference")
            lines.append(f"| `{st['scenario']}` | {st['wind_speed']:g} | "
                         f"{st['linear_pitching_zeta']:.3f} | {r['policy']} | {r['zeta']:.3f} | "
                         f"{diff} |")
    return "\n".join(lines) + "\n"


def pitch_fit_coverage(params, policies, speeds=(5.0, 10.0, 15.0), seeds=(5000, 5001, 5002),
                       obs_noise: float = SENSOR_NOISE) -> dict:
    """How many of the evaluator's pitch fits on an aerostat caught one of its fast modes:
    each named policy in every recover scenario at ``speeds`` and ``seeds`` (the report suite's
    sensor noise by default), fitted as :func:`~.evaluate.episode_metrics` fits them (guided on
    any aerostat but the baseline). Returns the number of fits, how many read n/a (more than
    :data:`~.fit_guides.FAST_MODE_FACTOR` from both linear fast modes, or no oscillation
    found), the largest ratio among the others (:meth:`~.fit_guides.FitGuides.fast_mode_ratio`)
    and whether the fits were guided."""
    params = as_params(params)
    cells = {scenario: (list(speeds), list(seeds)) for scenario in RECOVER_SCENARIOS}
    fits = stray = 0
    worst = 1.0
    for name in policies:
        policy = load_policy(name, params=params, obs_noise=obs_noise,
                             wind_range=cells_wind_range(cells, params))
        for _, ep in cells_episodes(policy, cells, obs_noise, params=params):
            for i in range(len(ep.speeds)):
                m = episode_metrics(ep, i)
                g = fit_guides(params, float(ep.speeds[i]))
                ratio = g.fast_mode_ratio(m["pitch_zeta"], m["pitch_period_s"])
                fits += 1
                if ratio > FAST_MODE_FACTOR:
                    stray += 1
                else:
                    worst = max(worst, ratio)
    return {"fits": fits, "stray": stray, "worst_ratio": worst, "guided": not is_baseline(params)}
