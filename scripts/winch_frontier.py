"""Frontier figures of the winch baselines: pendulum damping ratio against peak reel speed at 5, 10
and 15 m/s for the passive (braked) winch, the LQR, the LQG and the modal controller's curve,
measured in the environment (swing recovery, steady wind) next to each design's linear value.

Usage::

    PYTHONPATH=. python scripts/winch_frontier.py [--swing 10] [--json out.json]

Brake logic per row: "dead band" is the shipped rule (brake below 0.02 m/s), "off" the dead band
removed (winch.brake_speed = 0), "dwell" the dwell-time rule (brake after 10 s inside a 0.002 m/s
stand-still band) run through simulate() (full-state policies only). The LQG reads the standard observation with sensor noise
obs_noise = 0.01 (scaled units) and its filter is designed for that noise.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from aerostat_gym.agents.frontier import (
    initial_deviation,
    linear_fit_zeta,
    modal_linear_peak,
    swing_response,
)
from aerostat_gym.agents.lqg import LQGPolicy, LQGSchedule
from aerostat_gym.agents.lqr import LQRPolicy, LQRSchedule
from aerostat_gym.agents.modal import ModalPolicy, ModalSchedule, default_zeta
from aerostat_gym.agents.policies import PassivePolicy
from aerostat_gym.params import load_params

SPEEDS = (5.0, 10.0, 15.0)
MODAL_ZETAS = {5.0: (0.16, 0.18, 0.20, 0.22, 0.25), 10.0: (0.35, 0.45, 0.55, 0.60, 0.70),
               15.0: (0.45, 0.60, 0.75, 0.85, 0.95)}
LQG_NOISE = 0.01


def _row(policy, brake, predicted, run, linear_fit=(float("nan"), float("nan"))):
    return {"policy": policy, "brake": brake, "predicted_zeta": predicted,
            "linear_fit_zeta": linear_fit[0], "linear_drift_zeta": linear_fit[1], **run.row()}


def baselines_at(params, U, swing):
    """Passive, LQR and LQG rows at one wind speed."""
    rows = []
    lqr = LQRSchedule(params, speeds=np.array([U]))
    d = lqr.designs[0]
    pred = float(d.mode("pendulum").zeta)
    dx0 = np.append(initial_deviation(U, swing, params), 0.0)
    lin = linear_fit_zeta(d.closed_loop_matrix, d.K, dx0, d.linear.layout.cm_pos.start)
    braked = float(lqr.designs[0].mode("pendulum", "braked").zeta)
    rows.append(_row("passive", "dead band", braked, swing_response(PassivePolicy(), U, swing)))
    pol = LQRPolicy(params, schedule=lqr)
    for brake, run in (("dead band", swing_response(pol, U, swing, brake_speed=0.02,
                                                    brake_dwell=0.0)),
                       ("off", swing_response(pol, U, swing, brake_speed=0.0)),
                       ("dwell", swing_response(pol, U, swing, params=params))):
        rows.append(_row("lqr", brake, pred, run, lin))
    lqg = LQGPolicy(params, schedule=LQGSchedule(params, speeds=np.array([U]),
                                                 obs_noise=LQG_NOISE))
    for brake, bs in (("dead band", None), ("off", 0.0)):
        run = swing_response(lqg, U, swing, brake_speed=bs, obs_noise=LQG_NOISE, seed=3)
        rows.append(_row("lqg", brake, pred, run, lin))
    return rows


def modal_curve_at(params, U, swing, zetas):
    """The modal controller's frontier: one row per target damping ratio in ``zetas``."""
    rows = []
    dx0 = initial_deviation(U, swing, params)
    for z in zetas:
        sch = ModalSchedule(params, speeds=np.array([U]), zeta=z)
        pol = ModalPolicy(params, schedule=sch)
        d = sch.designs[0]
        lin = linear_fit_zeta(d.closed_loop_matrix, d.K_subset, dx0[d.index],
                              list(d.index).index(d.lqr.linear.layout.cm_pos.start))
        for brake, run in (("off", swing_response(pol, U, swing, brake_speed=0.0)),
                           ("dwell", swing_response(pol, U, swing, params=params))):
            row = _row("modal", brake, z, run, lin)
            row["linear_peak_set_point_m_s"] = modal_linear_peak(sch.designs[0], dx0)
            rows.append(row)
    return rows


def table(rows) -> str:
    head = ("| U [m/s] | policy | brake | designed zeta | linear: 1-mode fit | linear: drift "
            "fit | measured: 1-mode fit | measured: drift fit | peak set-point [m/s] | peak reel "
            "speed [m/s] | length wander [m] |\n|---|---|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        lines.append(f"| {r['wind_speed']:g} | {r['policy']} | {r['brake']} | "
                     f"{r['predicted_zeta']:.3f} | {r['linear_fit_zeta']:.3f} | "
                     f"{r['linear_drift_zeta']:.3f} | {r['zeta']:.3f} | {r['zeta_drift']:.3f} | "
                     f"{r['peak_set_point_m_s']:.3f} | "
                     f"{r['peak_reel_speed_m_s']:.3f} | {r['length_wander_m']:.2f} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--swing", type=float, default=10.0, help="initial along-wind swing [m]")
    ap.add_argument("--json", default=None, help="write the rows to this JSON file")
    ap.add_argument("--no-curve", action="store_true", help="modal controller at its default "
                    "schedule only (one row per speed) instead of the whole curve")
    args = ap.parse_args(argv)
    params = load_params()
    rows = []
    for U in SPEEDS:
        zetas = (default_zeta(U),) if args.no_curve else MODAL_ZETAS[U]
        rows += baselines_at(params, U, args.swing) + modal_curve_at(params, U, args.swing, zetas)
    print(f"swing {args.swing:g} m, steady wind, 180 s per run\n")
    print(table(rows))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
