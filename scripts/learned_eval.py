"""Issue 18 experiments: learned policies against the baselines on the damping task's returns,
the ``damping`` suite and a cut of the report protocol.

    PYTHONPATH=. python scripts/learned_eval.py passive lqg modal shipped \
        ppo=runs/exp/ppo_s0/ppo_final.zip --json runs/eval.json

Per policy (``label=path`` or a name load_policy knows):

- ``task``: mean return on TetheredAerostatDamping-v0 over the held-out seeds 1000-1019, and the
  paired difference to ``--reference`` (default: shipped) with its 95 % bootstrap interval;
- ``damping``: the damping suite (calm recover at 5, 10, 15 m/s, seed 0, no sensor noise):
  return and longitudinal pendulum zeta per speed;
- ``report cut``: with the report's sensor noise 0.01 and seeds 5000-5004, recover at 10 and
  15 m/s (return, zeta) and gusty_light / gusty at 8 and 12 m/s (return, RMS x).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from aerostat_gym.agents.evaluate import SENSOR_NOISE, episode_metrics, run_scenario
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.agents.protocol_stats import paired_difference_ci
from aerostat_gym.agents.returns import task_returns
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.envs.config import DEFAULT_WIND_RANGE

TASK = "TetheredAerostatDamping-v0"
CUT_SEEDS = [5000, 5001, 5002, 5003, 5004]
CUT = [("recover", [10.0, 15.0]), ("gusty_light", [8.0, 12.0]), ("gusty", [8.0, 12.0])]


def _cells(policy, scenario, speeds, seeds, noise):
    ep = run_scenario(policy, scenario, speeds, seeds, env_kwargs={"obs_noise": noise})
    rows = [episode_metrics(ep, i) for i in range(len(ep.speeds))]
    out = {}
    for u in speeds:
        sel = [r for r in rows if r["wind_speed"] == u]
        key = "pendulum_zeta" if scenario.startswith("recover") else "rms_x_m"
        out[f"{scenario}@{u:g}"] = {"return": float(np.mean([r["return"] for r in sel])),
                                    key: float(np.nanmean([r[key] for r in sel])),
                                    "terminated": int(sum(r["terminated"] for r in sel))}
    return out


def evaluate(label, name):
    t0 = time.perf_counter()
    returns = task_returns(name, TASK)
    res = {"task_returns": returns.tolist(), "task_mean": float(np.mean(returns))}
    pol0 = load_policy(name, wind_range=DEFAULT_WIND_RANGE, obs_noise=0.0)
    res["damping"] = _cells(pol0, "recover", [5.0, 10.0, 15.0], [0], 0.0)
    res["damping_score"] = float(np.mean([c["return"] for c in res["damping"].values()]))
    pol = load_policy(name, wind_range=DEFAULT_WIND_RANGE, obs_noise=SENSOR_NOISE)
    res["cut"] = {}
    for scenario, speeds in CUT:
        res["cut"].update(_cells(pol, scenario, speeds, CUT_SEEDS, SENSOR_NOISE))
    res["eval_wall_s"] = time.perf_counter() - t0
    return res


def main(argv=None):
    p = argparse.ArgumentParser(description=script_description(__doc__))
    p.add_argument("policies", nargs="+", help="NAME or LABEL=PATH")
    p.add_argument("--reference", default="shipped")
    p.add_argument("--json", default=None)
    p.add_argument("--table", default=None, help="print the table of a saved --json file")
    args = p.parse_args(argv)
    if args.table:
        with open(args.table) as fh:
            results = json.load(fh)
        print(table({k: v for k, v in results.items() if k in args.policies or
                     "all" in args.policies}, args.reference))
        return
    results = {}
    for item in args.policies:
        label, _, name = item.partition("=")
        results[label] = evaluate(label, name or label)
        print(f"{label}: done in {results[label]['eval_wall_s']:.0f} s", flush=True)
        if args.json:
            with open(args.json, "w") as fh:
                json.dump(results, fh, indent=1)
    ref = results.get(args.reference)
    if ref is None and args.reference:
        ref = evaluate(args.reference, args.reference)
    for label, r in results.items():
        if ref is not None and label != args.reference:
            d = paired_difference_ci(r["task_returns"], ref["task_returns"])
            r["vs_reference"] = {"mean": d.estimate, "low": d.low, "high": d.high}
    print(table(results, args.reference))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)


def table(results: dict, reference: str) -> str:
    """Markdown: task mean (and paired difference to the reference), damping-suite cells
    (return, zeta), report-cut cells (return, zeta or RMS x; 'T n': n terminations)."""
    first = next(iter(results.values()))
    cells = [("damping", c) for c in first["damping"]] + [("cut", c) for c in first["cut"]]
    lines = ["| policy | task mean | vs " + reference + " (95 % CI) | damping score | "
             + " | ".join(f"{c} {'calm' if g == 'damping' else 'noisy'}" for g, c in cells) + " |",
             "|" + "---|" * (4 + len(cells))]
    for label, r in results.items():
        vs = r.get("vs_reference")
        vs = f"{vs['mean']:+.1f} [{vs['low']:+.1f}, {vs['high']:+.1f}]" if vs else "-"
        parts = []
        for g, c in cells:
            cell = r[g][c]
            metric = cell.get("pendulum_zeta", cell.get("rms_x_m"))
            name = "z" if "pendulum_zeta" in cell else "x"
            term = f" T{cell['terminated']}" if cell["terminated"] else ""
            parts.append(f"{cell['return']:.1f} ({name} {metric:.3f}){term}")
        lines.append(f"| {label} | {r['task_mean']:.1f} | {vs} | {r['damping_score']:.1f} | "
                     + " | ".join(parts) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(run_script(main))
