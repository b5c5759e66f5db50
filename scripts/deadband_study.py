"""Command-path study: the report suite's aggregate and key cells for the braked winch, the
modal controller, ``modal_lqg`` and given policies, each also with a command deadband and
optionally a command low-pass added after the fact
(:class:`aerostat_gym.agents.residual.ShapedPolicy`), pooled by
:func:`aerostat_gym.agents.protocol.aggregate` (the episodes are those of ``aerostat-gym
evaluate --suite report``).

Usage::

    PYTHONPATH=. python scripts/deadband_study.py [--policy shipped] [--policy run/ppo_final.zip]
        [--deadband 0.05] [--lowpass 1.0] [--shaped modal_lqg]
        [--reference agents/baseline_report/report.json] [--json out.json]
        [--suite validation] [--results shaped.json]

About 2.5 minutes per policy on one core (report suite). ``--results`` writes the shaped
policies' episodes as a list of evaluation results, the format of ``report.json``, for
``scripts/poi_split.py`` and ``scripts/select_policy.py`` to read beside other reports.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from aerostat_gym.agents import protocol
from aerostat_gym.agents.evaluate import SENSOR_NOISE, suite_result
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.agents.report import load_results, policy_labels
from aerostat_gym.agents.residual import ShapedPolicy
from aerostat_gym.cli.common import nonneg_float, run_script, script_description
from aerostat_gym.params import load_params

#: (scenario, wind speed, metric) of the printed key-cell columns.
KEY_CELLS = (("recover", 10.0, "pendulum_zeta"), ("recover", 15.0, "pendulum_zeta"),
             ("recover", 10.0, "pitch_zeta"), ("recover", 15.0, "pitch_zeta"),
             ("recover", 15.0, "length_wander_m"), ("recover_small", 10.0, "return"))


def key_cells(result: dict) -> list[float]:
    row = []
    for sc, u, metric in KEY_CELLS:
        _, v = protocol.cell_values(result, sc, u, metric)
        row.append(float(np.nanmean(v)))
    return row


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--policy", action="append", default=None, metavar="NAME_OR_PATH",
                    help="a policy for load_policy (repeatable; default: shipped)")
    ap.add_argument("--deadband", type=nonneg_float, default=0.05,
                    help="deadband as a fraction of the winch's top speed (default 0.05)")
    ap.add_argument("--lowpass", type=nonneg_float, default=0.0,
                    help="command low-pass time constant [s] (default 0: none)")
    ap.add_argument("--shaped", action="append", default=None, metavar="NAME_OR_PATH",
                    help="the policies also run with the deadband and low-pass (repeatable; "
                         "default: every one but passive and modal)")
    ap.add_argument("--reference", action="append", default=None, metavar="REPORT_JSON",
                    help="read the unshaped policies' episodes from the report.json of an "
                         "`aerostat-gym evaluate --suite report` run instead of running them")
    ap.add_argument("--json", default=None, help="write the aggregate to this JSON file")
    ap.add_argument("--suite", default="report", choices=("report", "validation"),
                    help="the frozen suite to run (default: report)")
    ap.add_argument("--results", default=None,
                    help="write the shaped policies' episodes here (report.json format)")
    args = ap.parse_args(argv)
    params = load_params()
    names = ["passive", "modal", "modal_lqg"] + (args.policy or ["shipped"])
    shaped = args.shaped or [n for n in names if n not in ("passive", "modal")]
    stored = load_results(args.reference, policy_labels(names)) if args.reference else {}
    results = []
    for name, stored_label in zip(names, policy_labels(names), strict=True):
        if stored:
            results.append({**stored[stored_label], "label": name})
        if stored and name not in shaped:
            continue
        pol = load_policy(name, params=params, obs_noise=SENSOR_NOISE)
        runs = [] if stored else [(name, pol)]
        if name in shaped:
            label = f"{name} deadband {args.deadband:g}" + (
                f" low-pass {args.lowpass:g} s" if args.lowpass else "")
            runs.append((label, ShapedPolicy(pol, args.deadband, args.lowpass)))
        for label, p in runs:
            t0 = time.perf_counter()
            results.append(suite_result(p, label, args.suite, params))
            print(f"  {label}: {time.perf_counter() - t0:.0f} s", flush=True)
    agg = protocol.aggregate(results)["aggregate"]
    keys = KEY_CELLS if args.suite == "report" else ()  # the key cells' speeds are the report's
    print(("| policy | IQM [95% CI] | P(> passive) | P(> modal_lqg) | P(> modal) | "
           + "".join(f"{m} {sc} {u:g} | " for sc, u, m in keys)).rstrip())
    print("|---" * (5 + len(keys)) + "|")
    for r in results:
        row, p = agg[r["label"]], agg[r["label"]]["p_improvement"]
        ps = [f"{p[o]['p']:.2f}" if o in p else "" for o in ("passive", "modal_lqg", "modal")]
        cells = key_cells(r) if keys else []
        print((f"| {r['label']} | {row['iqm']:.3f} [{row['iqm_ci'][0]:.3f}, {row['iqm_ci'][1]:.3f}]"
              f" | {' | '.join(ps)} | " + "".join(f"{v:.3f} | " for v in cells)).rstrip())
    if args.json:
        with open(args.json, "w") as f:
            json.dump(protocol.json_safe(agg), f, indent=1)
    if args.results:
        with open(args.results, "w") as f:
            json.dump(protocol.json_safe([r for r in results if r["label"] not in names]), f)
    return results


if __name__ == "__main__":
    raise SystemExit(run_script(main))
