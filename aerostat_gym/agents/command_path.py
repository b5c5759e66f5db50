"""What the command path buys without learning: a policy through the residual's command
low-pass (and deadband), judged cell by cell against issue 18's targets.

The shipped residual sends its command through a first-order low-pass and a deadband
(:class:`aerostat_gym.agents.residual.CommandShaper`). The low-pass is not free: it keeps the
winch set-point from stepping on the sensor noise at the pitching and axial-spring periods
(2-4 s), which lets the pitch oscillation decay faster in calm air, but it lags the pendulum
loop, which matters in turbulence where the winch is saturated. This module measures that
trade on cells the report suite never runs with: the report's wind speeds with the validation
seeds (:data:`STUDY_CELLS`). Each :class:`ShapedDesign` is scored with the targets of
:mod:`aerostat_gym.agents.selection` (the same checks that choose the shipped seed), and the
numbers behind them are kept: pendulum and pitch damping and length wander in ``recover``
(pitch as a paired interval against the braked winch), RMS along-wind displacement against
passive's in light and moderate turbulence.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..params import Params
from .authority import gust_rows, recover_rows
from .evaluate import (
    REPORT_RECOVER_SPEEDS,
    SENSOR_NOISE,
    VALIDATION_SEEDS,
    cells_result,
)
from .policies import load_policy
from .protocol import cell_values, paired_interval
from .residual import ShapedPolicy
from .selection import REQUIRED_BASELINES, target_checks

#: The report's wind speeds (recover 5 / 10 / 15 m/s; light and moderate turbulence at the
#: issue's 8-16 m/s) with the validation seeds, disjoint from the report's 5000-5019.
STUDY_CELLS = {
    "recover": (list(REPORT_RECOVER_SPEEDS), list(VALIDATION_SEEDS)),
    "gusty_light": ([8.0, 12.0, 16.0], list(VALIDATION_SEEDS)),
    "gusty": ([8.0, 12.0, 16.0], list(VALIDATION_SEEDS)),
}


@dataclass(frozen=True)
class ShapedDesign:
    """A policy (a :func:`load_policy` name or a saved model's path) with the command low-pass
    ``lowpass`` [s] and ``deadband`` (a fraction of the winch's top speed) put on its commands;
    with both zero, the policy as it is."""

    label: str
    base: str = "modal_lqg"
    lowpass: float = 0.0
    deadband: float = 0.0

    def policy(self, params: Params, dt: float = 0.2):
        pol = load_policy(self.base, params=params, dt=dt, obs_noise=SENSOR_NOISE)
        if self.lowpass == 0.0 and self.deadband == 0.0:
            return pol
        return ShapedPolicy(pol, deadband=self.deadband, lowpass=self.lowpass, dt=dt)


def lowpass_designs(taus, base: str = "modal_lqg", deadband: float = 0.0) -> list[ShapedDesign]:
    """One design per low-pass time constant in ``taus`` (0: none) on ``base``."""
    db = f", deadband {deadband:g}" if deadband else ""
    return [ShapedDesign(f"{base} low-pass {t:g} s{db}" if t else f"{base}{db}", base,
                         float(t), float(deadband)) for t in taus]


def _episodes(result: dict, scenario: str) -> list[dict]:
    return result["scenarios"][scenario]["episodes"]


def design_row(label: str, result: dict, baselines: dict, cells: dict) -> dict:
    """A design's summary: targets met of the selection's checks (and which were missed);
    its recover rows (:func:`aerostat_gym.agents.authority.recover_rows`) with modal's
    pendulum damping and wander beside them and the paired interval of its pitch damping minus
    passive's; its RMS x ratio to passive's in each turbulent cell (from
    :func:`aerostat_gym.agents.authority.gust_rows`)."""
    checks = target_checks(result, baselines)
    passive, speeds = baselines["passive"], cells["recover"][0]
    recover = recover_rows(label, _episodes(result, "recover"), _episodes(passive, "recover"),
                           speeds)
    modal = recover_rows("modal", _episodes(baselines["modal"], "recover"),
                         _episodes(passive, "recover"), speeds)
    for row, ref in zip(recover, modal, strict=True):
        u = row["wind_speed"]
        iv = paired_interval(cell_values(result, "recover", u, "pitch_zeta")[1],
                             cell_values(passive, "recover", u, "pitch_zeta")[1])
        row["pitch_zeta_change_ci"] = None if iv is None else [iv.low, iv.high]
        row["modal_pendulum_zeta"] = ref["pendulum_zeta"]
        row["modal_length_wander_m"] = ref["length_wander_m"]
    ratios = {f"{g['scenario']} {g['wind_speed']:g}": g["rms_x_ratio"]
              for sc in cells if sc != "recover"
              for g in gust_rows(label, _episodes(result, sc), _episodes(passive, sc), sc,
                                 cells[sc][0])}
    return {"label": label, "targets_met": sum(c["met"] for c in checks),
            "targets": len(checks),
            "missed": [f"{c['target']} ({c['scenario']} {c['wind_speed']:g} m/s)"
                       for c in checks if not c["met"]],
            "recover": recover, "rms_x_ratio": ratios}


def command_path_study(params: Params, designs, cells: dict | None = None,
                       progress=None) -> dict:
    """Run the selection's baselines (passive, modal, LQG) and every design on ``cells``
    (default :data:`STUDY_CELLS`) with the report's sensor noise; returns {"cells", "designs":
    [:func:`design_row`, ...]}. ``progress(label)`` is called before each run."""
    cells = cells or STUDY_CELLS
    missing = [sc for sc in STUDY_CELLS if sc not in cells]
    if missing:
        raise ValueError(f"the study's cells must hold every scenario the targets read "
                         f"({list(STUDY_CELLS)}); missing {missing}")

    def run(label, policy):
        if progress is not None:
            progress(label)
        return cells_result(policy, label, cells, SENSOR_NOISE, params)

    policies = [(d.label, d.policy(params)) for d in designs]  # a bad path fails here, first
    baselines = {name: run(name, load_policy(name, params=params, obs_noise=SENSOR_NOISE))
                 for name in REQUIRED_BASELINES}
    rows = [design_row(label, run(label, pol), baselines, cells) for label, pol in policies]
    return {"cells": {sc: {"speeds": list(s), "seeds": list(n)} for sc, (s, n) in cells.items()},
            "designs": rows}


def _ci(iv) -> str:
    return "" if iv is None else f" [{iv[0]:+.4f}, {iv[1]:+.4f}]"


def study_markdown(study: dict) -> str:
    """The study as three Markdown tables: targets met, recover, turbulence."""
    rows = study["designs"]
    out = ["| design | targets met | missed |", "|---|---|---|"]
    out += [f"| {r['label']} | {r['targets_met']} / {r['targets']} | "
            f"{'; '.join(r['missed']) or 'none'} |" for r in rows]
    out += ["", "| design | U [m/s] | pendulum zeta (modal) | pitch zeta - passive [95 % CI] | "
            "length wander [m] (modal) |", "|---|---|---|---|---|"]
    for r in rows:
        out += [f"| {r['label']} | {c['wind_speed']:g} | {c['pendulum_zeta']:.3f} "
                f"({c['modal_pendulum_zeta']:.3f}) | {c['pitch_zeta_change']:+.4f}"
                f"{_ci(c['pitch_zeta_change_ci'])} | {c['length_wander_m']:.2f} "
                f"({c['modal_length_wander_m']:.2f}) |" for c in r["recover"]]
    keys = list(rows[0]["rms_x_ratio"]) if rows else []
    out += ["", "| design | " + " | ".join(f"RMS x / passive, {k} m/s" for k in keys) + " |",
            "|---|" + "---|" * len(keys)]
    out += [f"| {r['label']} | " + " | ".join(f"{r['rms_x_ratio'][k]:.3f}" for k in keys) + " |"
            for r in rows]
    return "\n".join(out)
