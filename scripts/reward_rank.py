"""Does the environment's reward (the winch-control score) rank the winch baselines the way the
pendulum damping does?

Runs every free-response scenario of the evaluator (``recover``, ``recover_small``,
``recover_cross``, ``recover_cross_small``, ``recover_combined``, ``recover_combined_small``) for
passive, tension feedback, LQR, modal and LQG at 3, 5, 7.5, 10, 12.5 and 15 m/s
(:mod:`aerostat_gym.agents.score_rank`), and per cell compares the episode return with the
fitted damping of the swung pendulum: Spearman rank correlation across the five policies, and
whether the best-return policy is the best-damping one.

Usage::

    PYTHONPATH=. python scripts/reward_rank.py [--json out.json]
"""

from __future__ import annotations

import argparse
import json

from aerostat_gym.agents.score_rank import rank_cells, rank_rows, summary
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__),
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--json", default=None, help="write the cells to this JSON file")
    args = ap.parse_args(argv)
    cells = rank_cells(rank_rows(load_params()))
    print("| scenario | U [m/s] | returns (passive, tension, lqr, modal, lqg) | damping | "
          "Spearman | best return = best damping |\n|---|---|---|---|---|---|")
    for c in cells:
        print(f"| {c['scenario']} | {c['wind_speed']:g} | "
              f"{', '.join(f'{v:.1f}' for v in c['returns'])} | "
              f"{', '.join(f'{v:.3f}' for v in c['zetas'])} | {c['rho']:.2f} | "
              f"{'yes' if c['best_agrees'] else 'no'} |")
    s = summary(cells)
    print(f"\nmean Spearman {s['mean_rho']:.2f} over all {s['cells']} cells, "
          f"{s['mean_rho_ranked']:.2f} over the {s['ranked_cells']} cells whose damping ratios "
          f"span at least {s['min_span']:g}; best return = best damping in {s['best_agrees']} of "
          f"{s['cells']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"cells": cells, "summary": s}, fh, indent=1)


if __name__ == "__main__":
    raise SystemExit(run_script(main))
