"""Frontier of the winch policies: pendulum damping ratio against peak reel speed at 5, 10 and
15 m/s for the passive (braked) winch, tension feedback, the LQR, the LQG, the modal gains on
the LQG's filter (modal_lqg, and the same through the shipped command path: modal_lqg_shaped),
the modal controller's curve and the learned policies, measured in the environment (swing
recovery, steady wind, the shipped winch and its brake logic), with the modal line's linear end
at the winch's speed limit.

Usage::

    PYTHONPATH=. python scripts/winch_frontier.py [--swing 10] [--policy shipped ...]
        [--json docs/figures/frontier.json] [--plot docs/figures/frontier.png]

Every run uses the full-state environment without sensor noise except the filtering
baselines (LQG, modal_lqg, modal_lqg_shaped) and the learned policies (``--policy``,
repeatable: a name for :func:`aerostat_gym.agents.policies.load_policy` or a path to an SB3
.zip; default the shipped policy), which read the standard observation with sensor noise LQG_NOISE (scaled units, seed
LQG_SEED): the noise the filters are designed for and the shipped policy was trained with. The
learned policies act deterministically.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from aerostat_gym.agents.frontier import (
    frontier_table,
    initial_deviation,
    linear_fit_zeta,
    modal_fractions,
    modal_peak_limit,
    plot_frontier,
    saturated_speeds,
    swing_response,
)
from aerostat_gym.agents.lqg import LQGPolicy, LQGSchedule
from aerostat_gym.agents.lqr import LQRPolicy, LQRSchedule
from aerostat_gym.agents.modal import ModalPolicy, ModalSchedule
from aerostat_gym.agents.policies import (
    PassivePolicy,
    TensionFeedbackPolicy,
    load_policy,
    shaped_command,
)
from aerostat_gym.agents.protocol import json_safe
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params

SPEEDS = (5.0, 10.0, 15.0)
#: Target pendulum damping ratios of the modal controller's curve per wind speed.
MODAL_ZETAS = {5.0: (0.16, 0.18, 0.20, 0.22, 0.25), 10.0: (0.35, 0.45, 0.55, 0.60, 0.70),
               15.0: (0.45, 0.60, 0.75, 0.85, 0.95)}
#: Sensor noise (scaled units) of the filtering baselines' and the learned policies' runs and
#: of the filters' design.
LQG_NOISE = 0.01
#: Reset seed of the noisy runs (draws the sensor noise).
LQG_SEED = 3
#: Learned policies run by default.
DEFAULT_POLICIES = ("shipped",)

table = frontier_table
plot = plot_frontier

_NAN = (math.nan, math.nan)


def _row(policy, kind, designed, run, linear_fit=_NAN) -> dict:
    return {"policy": policy, "kind": kind, "designed_zeta": designed,
            "linear_fit_zeta": linear_fit[0], "linear_drift_zeta": linear_fit[1], **run.row()}


def baselines_at(params, U, swing) -> list[dict]:
    """Passive, tension-feedback, LQR, LQG, modal_lqg and modal_lqg_shaped rows at one wind
    speed."""
    lqr = LQRSchedule(params, speeds=np.array([U]))
    d = lqr.designs[0]
    designed = float(d.mode("pendulum").zeta)
    dx0 = np.append(initial_deviation(U, swing, params), 0.0)
    lin = linear_fit_zeta(d.closed_loop_matrix, d.K, dx0, d.linear.layout.cm_pos.start)
    braked = float(d.mode("pendulum", "braked").zeta)
    lqg = LQGPolicy(params, schedule=LQGSchedule(params, speeds=np.array([U]),
                                                 obs_noise=LQG_NOISE))
    modal_lqg = LQGPolicy(params, schedule=LQGSchedule(params, speeds=np.array([U]),
                                                       obs_noise=LQG_NOISE, gains="modal"))
    modal_zeta = modal_lqg.schedule.designs[0].modes["pendulum"]["closed"]["zeta"]
    shaped = shaped_command(LQGPolicy(params, schedule=modal_lqg.schedule))
    return [
        _row("passive", "passive", braked, swing_response(PassivePolicy(), U, swing)),
        _row("tension", "baseline", None,
             swing_response(TensionFeedbackPolicy.for_params(params), U, swing)),
        _row("lqr", "baseline", designed,
             swing_response(LQRPolicy(params, schedule=lqr), U, swing), lin),
        _row("lqg", "baseline", designed,
             swing_response(lqg, U, swing, obs_noise=LQG_NOISE, seed=LQG_SEED), lin),
        _row("modal_lqg", "baseline", modal_zeta,
             swing_response(modal_lqg, U, swing, obs_noise=LQG_NOISE, seed=LQG_SEED)),
        _row("modal_lqg_shaped", "baseline", modal_zeta,
             swing_response(shaped, U, swing, obs_noise=LQG_NOISE, seed=LQG_SEED)),
    ]


def modal_curve_at(params, U, swing, zetas) -> list[dict]:
    """The modal controller's curve: one row per target damping ratio in ``zetas``."""
    rows = []
    dx0 = initial_deviation(U, swing, params)
    for z in zetas:
        sch = ModalSchedule(params, speeds=np.array([U]), zeta=z)
        d = sch.designs[0]
        lin = linear_fit_zeta(d.closed_loop_matrix, d.K_subset, dx0[d.index],
                              list(d.index).index(d.lqr.linear.layout.cm_pos.start))
        run = swing_response(ModalPolicy(params, schedule=sch), U, swing)
        rows.append(_row("modal", "modal", float(z), run, lin))
    return rows


def learned_at(policies: dict, U, swing) -> list[dict]:
    """One row per learned policy (label -> policy) at one wind speed."""
    return [_row(label, "learned", None,
                 swing_response(pol, U, swing, obs_noise=LQG_NOISE, seed=LQG_SEED))
            for label, pol in policies.items()]


def limits_at(params, speeds, swing, rows) -> list[dict]:
    """The modal line's linear end at the winch's speed limit per wind speed; ``authority``
    where a measured modal run saturates the winch (the end is then the authority bound)."""
    vmax = float(params.winch.max_speed)
    saturated = saturated_speeds(rows, vmax)
    out = []
    for U in speeds:
        z, peak = modal_peak_limit(params, U, swing, peak=vmax)
        out.append({"wind_speed": float(U), "zeta": float(z), "peak_set_point_m_s": float(peak),
                    "authority": float(U) in saturated})
    return out


def limits_text(limits) -> str:
    parts = []
    for b in limits:
        s = f"ζ {b['zeta']:.3f} at {b['wind_speed']:g} m/s (peak set-point {b['peak_set_point_m_s']:.3f})"
        if b["authority"]:
            s += ", the winch saturates: authority bound"
        parts.append(s)
    return "Modal line's linear end at the winch limit: " + "; ".join(parts) + "."


def _label(name: str) -> str:
    return Path(name).stem if name.endswith(".zip") else name


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--swing", type=float, default=10.0, help="initial along-wind swing [m]")
    ap.add_argument("--policy", action="append", default=None, metavar="NAME_OR_PATH",
                    help="learned policy to add (repeatable; default: shipped)")
    ap.add_argument("--json", default=None, help="write rows and limits to this JSON file")
    ap.add_argument("--plot", default=None, help="write the figure to this PNG file")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    params = load_params()
    learned = {_label(n): load_policy(n, params) for n in (args.policy or DEFAULT_POLICIES)}
    rows = []
    for U in SPEEDS:
        rows += (baselines_at(params, U, args.swing) + learned_at(learned, U, args.swing)
                 + modal_curve_at(params, U, args.swing, MODAL_ZETAS[U]))
    limits = limits_at(params, SPEEDS, args.swing, rows)
    print(f"swing {args.swing:g} m, steady wind, shipped winch, 180 s per run\n")
    print(table(rows))
    print()
    print(limits_text(limits))
    fractions = modal_fractions(rows)
    print("\nDamping over the modal curve's at the same peak reel speed (single-mode fit):")
    for f in fractions:
        print(f"  {f['wind_speed']:g} m/s {f['policy']}: {f['zeta']:.3f} / "
              f"{f['modal_at_same_peak']:.3f} = {f['fraction']:.2f} at "
              f"{f['peak_reel_speed_m_s']:.3f} m/s" + ("" if f["within_curve"] else
                                                        " (outside the curve's range)"))
    out = {"swing_m": args.swing, "lqg_noise": LQG_NOISE, "lqg_seed": LQG_SEED,
           "max_speed_m_s": float(params.winch.max_speed), "rows": rows, "limits": limits,
           "modal_fractions": fractions}
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        with open(args.json, "w") as fh:
            json.dump(json_safe(out), fh, indent=1)
    if args.plot:
        Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
        plot(rows, limits, args.plot, max_speed=float(params.winch.max_speed), swing=args.swing)
    print(f"\n{time.perf_counter() - t0:.0f} s")
    return out


if __name__ == "__main__":
    raise SystemExit(run_script(main))
