"""The learning curve on the training task: each run's checkpoints on fresh seeds of the task
it was trained on, against its starting point (:mod:`aerostat_gym.agents.task_curve`).

Usage::

    PYTHONPATH=. python scripts/task_curve.py runs/exp/lp1_717_s0 ... runs/exp/lp1_717_s4 \\
        [--names "seed 0" ... "seed 4"] [--seeds 200] --out agents/ppo_training/task_curve

writes ``task_curve.json``, ``task_curve.md`` and ``task_curve.png`` under ``--out``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from aerostat_gym.agents.task_curve import (
    TASK_CURVE_SEEDS,
    curve_markdown,
    plot_curves,
    task_curve,
)
from aerostat_gym.cli.common import first_seeds, run_script, script_description


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("runs", nargs="+", help="training run directories")
    ap.add_argument("--names", nargs="*", default=None, help="one label per run (default: "
                    "the run directory's name)")
    ap.add_argument("--seeds", type=int, default=len(TASK_CURVE_SEEDS),
                    help="the first N seeds of the curve's (a smoke run)")
    ap.add_argument("--out", required=True, help="output folder")
    args = ap.parse_args(argv)
    names = args.names if args.names is not None else [Path(r).name for r in args.runs]
    if len(names) != len(args.runs) or len(set(names)) != len(names):
        raise SystemExit(f"--names needs one distinct label per run: {len(args.runs)} runs, "
                         f"names {names}")
    seeds = first_seeds(args.seeds, TASK_CURVE_SEEDS)
    curves = {n: task_curve(r, seeds) for n, r in zip(names, args.runs, strict=True)}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "task_curve.json").write_text(json.dumps(curves, indent=1))
    (out / "task_curve.md").write_text(curve_markdown(curves))
    plot_curves(curves, out / "task_curve.png")
    print(curve_markdown(curves))
    return curves


if __name__ == "__main__":
    raise SystemExit(run_script(main))
