"""Baseline table of the evaluation protocol in turbulence: every classical baseline (passive,
tension feedback, LQR, modal, LQG) on the ``gusty`` scenario (moderate von Karman turbulence,
no initial perturbation, 120 s) at 5, 10 and 15 m/s with 20 seeds per cell, sensor noise
obs_noise = 0.01 (scaled units) for every policy; per cell the mean of each figure with its 95 %
bootstrap interval and the paired difference against the passive winch, and across cells the
interquartile mean and probability of improvement of the normalised displacement score
(passive mean RMS displacement of the cell over the episode's RMS displacement).

Usage::

    PYTHONPATH=. python scripts/baseline_table.py [--seeds 20] [--json out.json]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from aerostat_gym.agents.evaluate import episode_metrics, run_scenario
from aerostat_gym.agents.lqg import LQGPolicy
from aerostat_gym.agents.lqr import LQRPolicy
from aerostat_gym.agents.modal import ModalPolicy
from aerostat_gym.agents.policies import PassivePolicy, TensionFeedbackPolicy
from aerostat_gym.agents.protocol_table import aggregate_table, cell_table, markdown
from aerostat_gym.params import load_params

SPEEDS = (5.0, 10.0, 15.0)
METRICS = ("rms_x_m", "rms_pitch_rad", "peak_tension_N", "winch_energy_J", "return")
NOISE = 0.01
FIRST_SEED = 1000  # disjoint from the training seeds and the shipped suites (0-109)


def policies(params):
    return {"passive": PassivePolicy(), "tension": TensionFeedbackPolicy(),
            "lqr": LQRPolicy(params), "modal": ModalPolicy(params),
            "lqg": LQGPolicy(params, obs_noise=NOISE)}


def cell_values(pols, U, seeds):
    """values[policy][metric] over the seeds of one gusty cell, and terminations."""
    values, ended = {}, {}
    for name, pol in pols.items():
        ep = run_scenario(pol, "gusty", [U], seeds, env_kwargs={"obs_noise": NOISE})
        rows = [episode_metrics(ep, i) for i in range(len(seeds))]
        values[name] = {m: np.array([r[m] for r in rows]) for m in METRICS}
        ended[name] = sum(r["ended"] is not None for r in rows)
    return values, ended


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20, help="seeds per cell")
    ap.add_argument("--json", default=None, help="write every table to this JSON file")
    args = ap.parse_args(argv)
    params = load_params()
    pols = policies(params)
    seeds = list(range(FIRST_SEED, FIRST_SEED + args.seeds))
    out, scores = {"cells": {}}, {name: [] for name in pols}
    for U in SPEEDS:
        values, ended = cell_values(pols, U, seeds)
        rows = cell_table(values, METRICS, "passive")
        out["cells"][f"gusty_{U:g}"] = {"rows": rows, "terminations": ended}
        print(f"\n### gusty, {U:g} m/s, {args.seeds} seeds (terminations: {ended})\n")
        print(markdown(rows))
        ref = float(np.mean(values["passive"]["rms_x_m"]))
        for name in pols:
            scores[name].append(ref / values[name]["rms_x_m"])
    agg = aggregate_table({k: np.column_stack(v) for k, v in scores.items()}, "passive")
    out["aggregate"] = agg
    print("\n### aggregate over the three cells: displacement score (passive = 1)\n")
    print(markdown(agg))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1, default=float)


if __name__ == "__main__":
    main()
