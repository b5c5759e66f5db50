"""Does the environment's reward rank the winch baselines the way the pendulum damping does?

Runs the evaluator's ``recover`` scenario (steady wind, 10 m along-wind swing and 0.05 rad pitch
kick, 180 s) for passive, tension feedback, LQR, modal and LQG at 3, 5, 7.5, 10, 12.5 and
15 m/s, and per wind speed compares the episode return (the env's default reward) with the
fitted pendulum damping ratio (single-mode and sinusoid-plus-drift fits) across the five
policies: Spearman rank correlation, and whether the best-return policy is the best-damping one.

Usage::

    PYTHONPATH=. python scripts/reward_rank.py [--json out.json]
"""

from __future__ import annotations

import argparse
import json

import numpy as np
from scipy import stats

from aerostat_gym.agents.evaluate import episode_metrics, run_scenario
from aerostat_gym.agents.lqg import LQGPolicy
from aerostat_gym.agents.lqr import LQRPolicy
from aerostat_gym.agents.metrics_drift import fit_pendulum_with_drift
from aerostat_gym.agents.modal import ModalPolicy
from aerostat_gym.agents.policies import PassivePolicy, TensionFeedbackPolicy
from aerostat_gym.params import load_params

SPEEDS = [3.0, 5.0, 7.5, 10.0, 12.5, 15.0]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=None, help="write the per-episode figures here")
    args = ap.parse_args(argv)
    params = load_params()
    pols = {"passive": PassivePolicy(), "tension": TensionFeedbackPolicy(),
            "lqr": LQRPolicy(params), "modal": ModalPolicy(params), "lqg": LQGPolicy(params)}
    rows = []
    for name, pol in pols.items():
        ep = run_scenario(pol, "recover", SPEEDS, [0])
        for i in range(len(SPEEDS)):
            m = episode_metrics(ep, i)
            drift = fit_pendulum_with_drift(ep.time, ep.x[i]).zeta
            rows.append({"policy": name, "wind_speed": SPEEDS[i], "return": m["return"],
                         "zeta": m["pendulum_zeta"], "zeta_drift": drift,
                         "ended": m["ended"]})
    print("| U [m/s] | returns (passive, tension, lqr, modal, lqg) | zeta drift fit | "
          "Spearman(return, zeta) | best return = best zeta |\n|---|---|---|---|---|")
    rhos, agree = [], 0
    for U in SPEEDS:
        cell = [r for r in rows if r["wind_speed"] == U]
        ret = np.array([r["return"] for r in cell])
        zd = np.array([r["zeta_drift"] for r in cell])
        rho = float(stats.spearmanr(ret, zd).statistic)
        same = int(np.argmax(ret) == np.argmax(zd))
        rhos.append(rho)
        agree += same
        print(f"| {U:g} | {', '.join(f'{v:.1f}' for v in ret)} | "
              f"{', '.join(f'{v:.3f}' for v in zd)} | {rho:.2f} | {'yes' if same else 'no'} |")
    print(f"\nmean Spearman {np.mean(rhos):.2f}; best-return = best-damping in {agree} of "
          f"{len(SPEEDS)} cells")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
